//! The learners' registry: the one place that maps a learner's name to its type, and through
//! its [`Learner::Section`] to its section of the configuration. The binary (`seads train`, its
//! `--algorithm` and `--help`), the sweeps and agents reach a learner through [`with_learner`];
//! configurations are checked by [`check`] (and [`complete`]). A new learner is a type implementing
//! [`Learner`] and [`InWords`], one line in the `registry!` list below, and its presets in
//! `crates/seads-run/configs/<name>/`, which the data side (manifests, reports) reads. The
//! learners beyond the paper's live in this module's folder: DIAYN ([`diayn`]) was added so.

use seads_run::Section;

use crate::{Hac, InWords, Learner, RlError, TaskSac, TrainConfig, Trainer};

pub mod diayn;

/// Work to do with the learner of an algorithm, whichever it is: a generic function that
/// [`with_learner`] calls with the algorithm's learner type.
pub trait WithLearner {
    /// What the work gives.
    type Output;
    /// Does the work with learner type `L`.
    fn run<L: InWords + Send>(self) -> Self::Output;
}

/// The registry: every learner type, each once. Its name is its section's
/// [`Section::ALGORITHM`].
macro_rules! registry {
    ($($learner:ty),+ $(,)?) => {
        /// Does `work` with the learner named `algorithm`; an error names the learners there are.
        ///
        /// ```
        /// use seads_rl::{InWords, WithLearner, with_learner};
        /// /// The checkpoint files a learner keeps only for resuming.
        /// struct ResumeOnly;
        /// impl WithLearner for ResumeOnly {
        ///     type Output = Vec<&'static str>;
        ///     fn run<L: InWords + Send>(self) -> Vec<&'static str> {
        ///         L::resume_only_files()
        ///     }
        /// }
        /// assert!(!with_learner("seads", ResumeOnly)?.is_empty());
        /// assert!(with_learner("nobody", ResumeOnly).is_err());
        /// # Ok::<(), seads_rl::RlError>(())
        /// ```
        pub fn with_learner<W: WithLearner>(algorithm: &str, work: W) -> Result<W::Output, RlError> {
            $(
                if algorithm == name::<$learner>() {
                    return Ok(work.run::<$learner>());
                }
            )+
            let mut names = names();
            names.sort_unstable();
            Err(RlError::config(format!(
                "unknown learner {algorithm:?} (one of {})",
                names.join(", ")
            )))
        }

        /// The names of every learner, in the registry's order.
        pub fn names() -> Vec<&'static str> {
            vec![$(name::<$learner>()),+]
        }
    };
}

registry![Trainer, TaskSac, Hac, diayn::Diayn];

/// The name of learner `L`.
fn name<L: Learner>() -> &'static str {
    <L::Section as Section>::ALGORITHM
}

/// Checks `config`'s learner: a learner of the registry, and its section with its own checks
/// ([`Section::validate`]).
pub fn check(config: &TrainConfig) -> Result<(), RlError> {
    complete(&mut config.clone())
}

/// Checks `config`'s learner as [`check`] does, and writes its section out in full (every field,
/// its defaults included), as a run's `config.toml` holds it.
pub fn complete(config: &mut TrainConfig) -> Result<(), RlError> {
    struct Complete<'a>(&'a mut TrainConfig);
    impl WithLearner for Complete<'_> {
        type Output = Result<(), RlError>;
        fn run<L: InWords + Send>(self) -> Result<(), RlError> {
            Ok(self.0.learner.complete::<L::Section>()?)
        }
    }
    let algorithm = config.algorithm().to_owned();
    with_learner(&algorithm, Complete(config))?
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The registry and the presets name the same learners: each learner has presets (which the
    /// data side reads), and each folder of presets a learner.
    #[test]
    fn every_learner_has_presets_and_every_preset_a_learner() {
        let mut registered = names();
        registered.sort_unstable();
        assert_eq!(registered, seads_run::learner_names());
        for algorithm in names() {
            for (env, config) in TrainConfig::presets_of(algorithm) {
                let config = config.unwrap_or_else(|e| panic!("{algorithm} on {env}: {e}"));
                check(&config).unwrap();
                assert_eq!(config.algorithm(), algorithm);
            }
        }
    }

    /// A section with a value its learner refuses, or of another learner, fails the check in
    /// one line.
    #[test]
    fn a_bad_section_fails_the_check() {
        let mut config = TrainConfig::preset_for("lightsout-cursor", "hac").unwrap();
        config.learner = seads_run::LearnerConfig::stated(
            "hac",
            Some(("hac".into(), "subgoal_horizon = 0".parse().unwrap())),
        );
        let e = check(&config).unwrap_err().to_string();
        assert!(e.contains("hac.subgoal_horizon must be at least 1"), "{e}");
        config.learner =
            seads_run::LearnerConfig::stated("hac", Some(("seads".into(), toml::Table::new())));
        let e = check(&config).unwrap_err().to_string();
        assert!(
            e.contains("[seads] is no section of algorithm \"hac\""),
            "{e}"
        );
        config.learner = seads_run::LearnerConfig::stated("nobody", None);
        let e = check(&config).unwrap_err().to_string();
        assert!(
            e.contains("unknown learner \"nobody\" (one of diayn, hac, sac, seads)"),
            "{e}"
        );
    }
}
