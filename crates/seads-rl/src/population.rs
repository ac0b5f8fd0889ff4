//! Populations: several runs whose networks have the same shapes, trained in one process, epoch
//! by epoch in lockstep. Each member is a whole [`Run`] in its own directory, written exactly as
//! a run trained alone writes it, so a member resumes, evaluates and reports as a single run.
//!
//! On the CPU the members' epochs run side by side on the process's threads, each member with
//! its own networks and one libtorch thread. Stacking the members' weights into one batched
//! product per layer would not repeat a member's solo run: on the CPU the weight gradients of a
//! stacked `baddbmm` differ from each member's `linear` for the first layers of the actor (78
//! inputs) and of the forward model (50), by up to 1.2e-5 (`examples/stacked_vs_solo.rs`,
//! `docs/results/population/stacked-vs-solo.json`). Keeping each member's own kernels makes a
//! population a pure speed feature on the CPU, whose members' metrics equal their solo runs'
//! row for row (`crates/seads-cli/tests/end_to_end/population.rs`).

use std::sync::Mutex;

use crate::learner::Learner;
use crate::run::{Run, RunEvent};
use crate::{RlError, TrainConfig, Trainer};

/// What members of one population must share: everything that fixes the shapes of their
/// networks and environments, and what is set per process (kernels, device). Settings such as
/// seeds, learning rates or relabelling may differ.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PopulationKey(String);

impl PopulationKey {
    /// The key of a run with `config`.
    pub fn of(config: &TrainConfig) -> Self {
        let values: Vec<String> = Self::fields(config).into_iter().map(|(_, v)| v).collect();
        Self(values.join("|"))
    }

    /// Why `a` and `b` cannot share a population (the first field that differs), if they cannot.
    pub fn mismatch(a: &TrainConfig, b: &TrainConfig) -> Option<String> {
        Self::fields(a)
            .into_iter()
            .zip(Self::fields(b))
            .find(|((_, x), (_, y))| x != y)
            .map(|((field, x), (_, y))| format!("{field} differs ({x} against {y})"))
    }

    /// The settings members must share, named as in `config.toml`, in words.
    fn fields(c: &TrainConfig) -> [(&'static str, String); 8] {
        let env_config = serde_json::to_string(&c.env_config).unwrap_or_default();
        [
            ("algorithm", c.algorithm.name().to_owned()),
            ("env", c.env.clone()),
            ("env_config", env_config),
            ("num_skills", format!("{:?}", c.seads.num_skills)),
            ("sac.hidden", format!("{:?}", c.sac.hidden)),
            (
                "skill_model",
                format!(
                    "{:?} {:?}",
                    c.seads.skill_model.kind, c.seads.skill_model.hidden
                ),
            ),
            ("portable_numerics", c.portable_numerics.to_string()),
            ("device", c.device.to_string()),
        ]
    }
}

/// Checks that runs with `configs` can train as one population: at least one member, and every
/// member's [`PopulationKey`] equal to the first's. The error names the first member that differs
/// and the field.
pub fn check_population(configs: &[(String, TrainConfig)]) -> Result<(), RlError> {
    let Some((first_name, first)) = configs.first() else {
        return Err(RlError::Config(
            "a population needs at least one run".into(),
        ));
    };
    for (name, config) in &configs[1..] {
        if let Some(why) = PopulationKey::mismatch(first, config) {
            return Err(RlError::Config(format!(
                "{name} cannot train in one population with {first_name}: {why}"
            )));
        }
    }
    Ok(())
}

/// Runs trained together: one epoch of every unfinished member per [`Population::step`].
pub struct Population<L: Learner = Trainer> {
    members: Vec<Run<L>>,
    threads: usize,
}

impl<L: Learner + Send> Population<L>
where
    L::Stats: Send,
    L::Metrics: Send,
{
    /// A population of `members` (checked with [`check_population`]) whose epochs run on up to
    /// `threads` threads at once.
    pub fn new(members: Vec<Run<L>>, threads: usize) -> Result<Self, RlError> {
        check_members(&members)?;
        Ok(Self {
            members,
            threads: threads.max(1),
        })
    }

    /// The members, handed back.
    pub fn into_members(self) -> Vec<Run<L>> {
        self.members
    }
}

/// [`check_population`] of the runs `members`.
pub(crate) fn check_members<L: Learner>(members: &[Run<L>]) -> Result<(), RlError> {
    let configs: Vec<(String, TrainConfig)> = members
        .iter()
        .map(|m| (m.dir().display().to_string(), m.trainer().config().clone()))
        .collect();
    check_population(&configs)
}

impl<L: Learner + Send> Members for Population<L>
where
    L::Stats: Send,
    L::Metrics: Send,
{
    type Learner = L;

    fn members(&self) -> &[Run<L>] {
        &self.members
    }

    fn members_mut(&mut self) -> &mut [Run<L>] {
        &mut self.members
    }

    /// The members' epochs run side by side ([`Run::step`]); a member's result does not depend
    /// on which thread runs it or when. The first error of a member is returned once every
    /// member's epoch has ended.
    fn step(&mut self) -> Result<Vec<Option<RunEvent<L>>>, RlError> {
        let unfinished = unfinished(&mut self.members);
        let results = on_threads(unfinished, self.threads, |(i, member)| (i, member.step()));
        events(&self.members, results)
    }
}

/// Runs trained together, epoch by epoch: a [`Population`], or a
/// [`StackedPopulation`](crate::StackedPopulation) whose SAC agents are stacked.
pub trait Members {
    /// What each member trains.
    type Learner: Learner;
    /// The members, in the order given.
    fn members(&self) -> &[Run<Self::Learner>];
    /// The members, to set hooks or read state.
    fn members_mut(&mut self) -> &mut [Run<Self::Learner>];
    /// One epoch of each unfinished member with its evaluation and checkpoint when due; `None`
    /// for a member that had finished.
    #[allow(clippy::type_complexity)] // one event per member
    fn step(&mut self) -> Result<Vec<Option<RunEvent<Self::Learner>>>, RlError>;
    /// Whether every member has spent its budget.
    fn finished(&self) -> bool {
        self.members().iter().all(Run::finished)
    }
}

/// The unfinished members with their positions.
pub(crate) fn unfinished<L: Learner>(members: &mut [Run<L>]) -> Vec<(usize, &mut Run<L>)> {
    members
        .iter_mut()
        .enumerate()
        .filter(|(_, m)| !m.finished())
        .collect()
}

/// One event per member from the `results` of the members at their positions (`None` for the
/// others), or the first member's error.
#[allow(clippy::type_complexity)] // one event per member
pub(crate) fn events<L: Learner>(
    members: &[Run<L>],
    results: Vec<(usize, Result<RunEvent<L>, RlError>)>,
) -> Result<Vec<Option<RunEvent<L>>>, RlError> {
    let mut events: Vec<Option<RunEvent<L>>> = members.iter().map(|_| None).collect();
    for (i, result) in results {
        events[i] = Some(result.map_err(|e| member_error(&members[i], e))?);
    }
    Ok(events)
}

/// A member's error, naming its directory.
pub(crate) fn member_error<L: Learner>(member: &Run<L>, e: RlError) -> RlError {
    RlError::Member {
        dir: member.dir().display().to_string(),
        source: Box::new(e),
    }
}

/// `f` applied to each of `items` on up to `threads` threads; the results in the order of
/// `items`.
pub(crate) fn on_threads<T: Send, R: Send>(
    items: Vec<T>,
    threads: usize,
    f: impl Fn(T) -> R + Sync,
) -> Vec<R> {
    let n = items.len();
    let mut results: Vec<Option<R>> = (0..n).map(|_| None).collect();
    let queue = Mutex::new(items.into_iter().zip(results.iter_mut()));
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1).min(n) {
            scope.spawn(|| {
                // A poisoned lock means an item panicked; the scope re-raises it.
                while let Some((item, slot)) = queue.lock().ok().and_then(|mut q| q.next()) {
                    *slot = Some(f(item));
                }
            });
        }
    });
    results.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_and_rates_share_a_key_shapes_and_environments_do_not() {
        let a = TrainConfig::preset("lightsout-cursor").unwrap();
        let mut b = a.clone();
        (b.seed, b.sac.lr, b.seads.relabel.sac_p) = (7, 1e-3, 0.0);
        assert_eq!(PopulationKey::of(&a), PopulationKey::of(&b));
        assert_eq!(PopulationKey::mismatch(&a, &b), None);
        b.sac.hidden = vec![128, 128];
        assert_ne!(PopulationKey::of(&a), PopulationKey::of(&b));
        let why = PopulationKey::mismatch(&a, &b).unwrap();
        assert!(why.starts_with("sac.hidden differs"), "{why}");
        let c = TrainConfig::preset("tileswap-cursor").unwrap();
        assert!(
            PopulationKey::mismatch(&a, &c)
                .unwrap()
                .starts_with("env differs")
        );
        assert!(check_population(&[]).is_err());
    }
}
