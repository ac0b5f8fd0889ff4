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
use crate::{RlError, TrainConfig, Trainer, check_population};

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
    Ok(check_population(&configs)?)
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
