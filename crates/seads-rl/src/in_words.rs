//! A learner's progress in words: what `seads train` shows of SEADS and of each baseline.

use crate::learner::Learner;
use crate::{Hac, TaskEpochStats, TaskMetrics, TaskSac, Trainer};

/// A learner's progress as a person reads it (`seads train` shows it): steps, and each
/// evaluation and the time per phase in a few words.
pub trait InWords: Learner {
    /// Environment steps so far.
    fn steps(&self) -> u64;
    /// What an evaluation found, in a few words ("coverage 24.10/25").
    fn headline(&self, m: &Self::Metrics) -> String;
    /// The time per phase, one line.
    fn phases(&self) -> String;
}

impl InWords for Trainer {
    fn steps(&self) -> u64 {
        self.env_steps()
    }
    fn headline(&self, m: &Self::Metrics) -> String {
        format!(
            "coverage {:>5.2}/{}  reward {:>6.2}",
            m.skill_coverage,
            self.num_skills(),
            m.mean_reward
        )
    }
    fn phases(&self) -> String {
        let t = self.timings();
        format!(
            "collect {:.1} s, relabel {:.1} s, skill model {:.1} s, SAC {:.1} s, evaluation {:.1} s",
            t.collect, t.relabel, t.skill_model, t.sac, t.evaluate
        )
    }
}

/// A task-reward baseline as a person reads it: all report [`TaskEpochStats`] and
/// [`TaskMetrics`], and differ only in what they add to the headline and in their phases.
pub trait BaselineInWords: Learner<Stats = TaskEpochStats, Metrics = TaskMetrics> {
    /// Environment steps so far.
    fn env_steps(&self) -> u64;
    /// What the baseline adds to an evaluation's headline ("" for none).
    fn extra(&self, m: &TaskMetrics) -> String;
    /// The time per phase, one line.
    fn phases(&self) -> String;
}

impl<B: BaselineInWords> InWords for B {
    fn steps(&self) -> u64 {
        self.env_steps()
    }
    fn headline(&self, m: &Self::Metrics) -> String {
        format!("{}{}", task_headline(m), self.extra(m))
    }
    fn phases(&self) -> String {
        BaselineInWords::phases(self)
    }
}

impl BaselineInWords for TaskSac {
    fn env_steps(&self) -> u64 {
        TaskSac::env_steps(self)
    }
    fn extra(&self, _: &TaskMetrics) -> String {
        String::new()
    }
    fn phases(&self) -> String {
        let t = self.timings();
        format!(
            "collect {:.1} s, SAC {:.1} s, evaluation {:.1} s",
            t.collect, t.sac, t.evaluate
        )
    }
}

impl BaselineInWords for Hac {
    fn env_steps(&self) -> u64 {
        Hac::env_steps(self)
    }
    fn extra(&self, m: &TaskMetrics) -> String {
        let recent = m.subgoals_reached.unwrap_or_default();
        format!(
            "  subgoals reached {:.1} % (since the last line)",
            100.0 * recent
        )
    }
    fn phases(&self) -> String {
        let t = self.timings();
        format!(
            "collect {:.1} s, SAC updates of both levels {:.1} s, evaluation {:.1} s",
            t.collect, t.sac, t.evaluate
        )
    }
}

/// A baseline's evaluation in a few words.
fn task_headline(m: &TaskMetrics) -> String {
    let per_depth: Vec<String> = m
        .success
        .iter()
        .map(|s| format!("{:.0}", 100.0 * s))
        .collect();
    format!(
        "task success {:>5.1} % (depths 1-5: {} %)  training episodes solved {:.1} %",
        100.0 * m.mean_success,
        per_depth.join("/"),
        100.0 * m.train_solved
    )
}
