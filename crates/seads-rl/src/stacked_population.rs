//! Populations whose members' SAC agents are stacked ([`StackedPopulation`]): per epoch the
//! members collect, relabel and update their skill models side by side on the CPU threads, as in
//! a [`Population`](crate::Population), while one thread takes every member's SAC steps at once
//! on the stacked weights ([`crate::stacked::StackedSac`]), on the CPU or a GPU. That is the
//! solo epoch ([`Trainer::run_epoch`]) cut at the same places, with the SAC steps of all members
//! in one batched product per layer.
//!
//! The stacked weights are the members' state while the population trains. After each epoch the
//! actors are written back into the members' own agents, which collect and evaluate with them;
//! the whole state (critics, targets, optimisers) before a member's checkpoint and whenever the
//! stacked members change. So each member's run directory is a single run's, and its checkpoint
//! resumes or evaluates as one.

use seads_nn::Resolve as _;
use std::time::Instant;

use tch::Device;

use crate::population::{Members, check_members, events, member_error, on_threads, unfinished};
use crate::run::due;
use crate::stacked::StackedSac;
use crate::{ComputeDevice, RlError, Run, RunEvent, Sac, Trainer};

/// SEADS runs trained together with stacked SAC agents: one epoch of every unfinished member per
/// [`Members::step`].
pub struct StackedPopulation {
    members: Vec<Run<Trainer>>,
    threads: usize,
    device: Device,
    /// The stacked agents of the members at these positions (those that updated last).
    stack: Option<(Vec<usize>, StackedSac)>,
}

impl StackedPopulation {
    /// A population of `members` (checked with [`check_population`](crate::check_population),
    /// and sharing `sac.batch_size` and `seads.updates_per_epoch`, the shapes of a stacked step)
    /// whose CPU work runs on up to `threads` threads and whose SAC agents are stacked on
    /// `device`. The members' own agents should be on the CPU, where they collect.
    pub fn new(
        members: Vec<Run<Trainer>>,
        threads: usize,
        device: ComputeDevice,
    ) -> Result<Self, RlError> {
        check_members(&members)?;
        if let Some((first, rest)) = members.split_first() {
            // SAC's minibatch size and SEADS's SAC steps per epoch.
            let shape = |run: &Run<Trainer>| {
                let config = run.trainer().config();
                let steps = config.seads().map_or(0, |s| s.updates_per_epoch);
                (config.sac.batch_size, steps)
            };
            let a = shape(first);
            for member in rest {
                let b = shape(member);
                for (field, x, y) in [
                    ("sac.batch_size", a.0, b.0),
                    ("seads.updates_per_epoch", a.1, b.1),
                ] {
                    if x != y {
                        return Err(RlError::config(format!(
                            "{} cannot train in one stacked population with {}: {field} differs \
                             ({y} against {x})",
                            member.dir().display(),
                            first.dir().display()
                        )));
                    }
                }
            }
        }
        Ok(Self {
            members,
            threads: threads.max(1),
            device: device.resolve()?,
            stack: None,
        })
    }

    /// The members, handed back with their whole state written into their own agents.
    pub fn into_members(mut self) -> Vec<Run<Trainer>> {
        self.unstack();
        self.members
    }

    /// Writes the stacked state back into the members it came from and drops the stack.
    fn unstack(&mut self) {
        if let Some((positions, stack)) = self.stack.take() {
            stack.unstack_into(&mut agents(&mut self.members, &positions));
        }
    }

    /// Stacks the agents of the members at `positions`, unless they are stacked already.
    fn restack(&mut self, positions: &[usize]) -> Result<(), RlError> {
        if self.stack.as_ref().is_some_and(|(p, _)| p == positions) {
            return Ok(());
        }
        self.unstack();
        if !positions.is_empty() {
            let sacs: Vec<&Sac> = positions
                .iter()
                .map(|&i| self.members[i].trainer().policy())
                .collect();
            let stack = StackedSac::stack(&sacs, self.device)?;
            self.stack = Some((positions.to_vec(), stack));
        }
        Ok(())
    }
}

/// The members at `positions` (increasing).
fn selected<'a>(members: &'a mut [Run<Trainer>], positions: &[usize]) -> Vec<&'a mut Run<Trainer>> {
    members
        .iter_mut()
        .enumerate()
        .filter(|(i, _)| positions.contains(i))
        .map(|(_, m)| m)
        .collect()
}

/// The own agents of the members at `positions` (increasing).
fn agents<'a>(members: &'a mut [Run<Trainer>], positions: &[usize]) -> Vec<&'a mut Sac> {
    selected(members, positions)
        .into_iter()
        .map(|m| m.parts().0.sac_mut())
        .collect()
}

impl Members for StackedPopulation {
    type Learner = Trainer;

    fn members(&self) -> &[Run<Trainer>] {
        &self.members
    }

    fn members_mut(&mut self) -> &mut [Run<Trainer>] {
        &mut self.members
    }

    /// Collection, then the stacked SAC steps beside the preparation of the next epoch's
    /// updates, then each member's evaluation and checkpoint when due. The first error of a
    /// member is returned once every member has finished the part that failed.
    fn step(&mut self) -> Result<Vec<Option<RunEvent<Trainer>>>, RlError> {
        let threads = self.threads;
        let collected = on_threads(unfinished(&mut self.members), threads, |(i, member)| {
            let first = member.trainer().epoch() == 0;
            let (trainer, hook) = member.parts();
            (i, first, trainer.collect(hook))
        });
        let mut epochs = Vec::with_capacity(collected.len());
        for (i, first, result) in collected {
            let epoch = result.map_err(|e| member_error(&self.members[i], e))?;
            epochs.push((i, first, epoch));
        }
        let mut updating = Vec::new();
        let mut work = Vec::new();
        for (i, _, epoch) in &mut epochs {
            if let Some(updates) = epoch.take_updates() {
                work.push(self.members[*i].parts().0.sac_work(updates));
                updating.push(*i);
            }
        }
        self.restack(&updating)?;

        let stack = self.stack.as_mut().map(|(_, stack)| stack);
        let positions: Vec<usize> = epochs.iter().map(|(i, ..)| *i).collect();
        let mut stepping = selected(&mut self.members, &positions);
        let sac = std::thread::scope(|scope| {
            let sac = scope.spawn(move || {
                // One libtorch thread: on the CPU a stacked step then repeats exactly.
                tch::set_num_threads(1);
                let start = Instant::now();
                let losses = stack.map(|stack| stack.update_epoch(&work)).transpose();
                (losses, start.elapsed().as_secs_f64())
            });
            let pairs: Vec<_> = stepping.iter_mut().zip(epochs.iter_mut()).collect();
            on_threads(pairs, threads, |(member, (_, _, epoch))| {
                let (trainer, hook) = member.parts();
                trainer.prepare_after(epoch, hook);
            });
            sac.join().expect("the stacked SAC thread")
        });
        let (losses, seconds) = sac;
        let mut losses = losses?.unwrap_or_default().into_iter();

        let mut concluded = Vec::with_capacity(epochs.len());
        let mut full = false;
        for (member, (i, first, epoch)) in stepping.iter_mut().zip(epochs) {
            let sac = updating
                .contains(&i)
                .then(|| (losses.next().unwrap_or_default(), seconds));
            let trainer = member.parts().0;
            let stats = trainer.conclude(epoch, sac);
            let (_, checkpoint) = due(trainer.config(), first, trainer.epoch(), trainer.finished());
            full |= checkpoint && updating.contains(&i);
            concluded.push((first, stats));
        }
        if let Some((positions, stack)) = &self.stack {
            let mut sacs = agents(&mut self.members, positions);
            if full {
                stack.unstack_into(&mut sacs);
            } else {
                stack.unstack_actors(&mut sacs);
            }
        }

        let stepping: Vec<_> = positions
            .iter()
            .zip(selected(&mut self.members, &positions))
            .zip(concluded)
            .collect();
        let results = on_threads(stepping, threads, |((&i, member), (first, stats))| {
            (i, member.after_epoch(first, stats))
        });
        events(&self.members, results)
    }
}
