//! A skill model built from its settings: the one place that knows every kind.

use tch::Device;

use crate::MixtureModel;
use crate::model::{
    ForwardModel, SkillDiscriminator, SkillModel, SkillModelConfig, SkillModelKind,
};

/// Builds a skill model from its settings ([`SkillModelConfig`], which lives with the run's
/// configuration in `seads-run`).
pub trait BuildSkillModel {
    /// The model for symbolic states of `d` bits and `k` skills, initialised from `seed`.
    fn build(&self, d: usize, k: usize, device: Device, seed: u64) -> Box<dyn SkillModel>;
}

impl BuildSkillModel for SkillModelConfig {
    fn build(&self, d: usize, k: usize, device: Device, seed: u64) -> Box<dyn SkillModel> {
        match self.kind {
            SkillModelKind::Forward => Box::new(ForwardModel::new(d, k, self, device, seed)),
            SkillModelKind::Mixture => Box::new(MixtureModel::new(d, k, self, device, seed)),
            SkillModelKind::Vic => Box::new(SkillDiscriminator::new(d, k, self, device, seed)),
        }
    }
}
