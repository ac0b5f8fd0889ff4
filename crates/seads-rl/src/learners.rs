//! The one place that maps an algorithm to its learner. The binary, sweeps and agents reach a
//! learner through [`with_learner`], so a new learner is a type implementing
//! [`Learner`](crate::Learner) and [`InWords`], a variant of [`Algorithm`], and one line here.

use crate::{Algorithm, Hac, InWords, TaskSac, Trainer};

/// Work to do with the learner of an algorithm, whichever it is: a generic function that
/// [`with_learner`] calls with the algorithm's learner type.
pub trait WithLearner {
    /// What the work gives.
    type Output;
    /// Does the work with learner type `L`.
    fn run<L: InWords + Send>(self) -> Self::Output;
}

/// Does `work` with the learner of `algorithm`.
///
/// ```
/// use seads_rl::{Algorithm, InWords, WithLearner, with_learner};
/// /// The checkpoint files a learner keeps only for resuming.
/// struct ResumeOnly;
/// impl WithLearner for ResumeOnly {
///     type Output = Vec<&'static str>;
///     fn run<L: InWords + Send>(self) -> Vec<&'static str> {
///         L::resume_only_files()
///     }
/// }
/// assert!(!with_learner(Algorithm::Seads, ResumeOnly).is_empty());
/// ```
pub fn with_learner<W: WithLearner>(algorithm: Algorithm, work: W) -> W::Output {
    match algorithm {
        Algorithm::Seads => work.run::<Trainer>(),
        Algorithm::Sac => work.run::<TaskSac>(),
        Algorithm::Hac => work.run::<Hac>(),
    }
}
