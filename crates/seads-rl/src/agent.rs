//! A trained agent loaded from a run directory: the skill policy (for executing skills) and the
//! forward model (for planning); and a baseline's task policy loaded from its checkpoint.

use seads_nn::Resolve as _;
use std::path::{Path, PathBuf};

use seads_embodiment::{EnvSpec, SkillPolicy, make_env};
use seads_games::Successor;
use seads_skillmodel::{ForwardModel, MixtureModel, PlanningModel, SkillModel, SkillModelKind};

use crate::episode::policy_input;
use crate::store::{checkpoints, latest_checkpoint};
use crate::task_policy::TaskPolicy;
use crate::{InWords, RlError, Sac, SeadsConfig, TrainConfig, WithLearner, load_config};
use seads_run::fitted::{FitRecord, fitted_model_dir, read_fit_record};

/// The skill policy π(a | s, k) of a trained agent, executed deterministically.
pub struct AgentPolicy {
    pub(crate) sac: Sac,
    k: usize,
}

impl SkillPolicy for AgentPolicy {
    fn num_skills(&self) -> usize {
        self.k
    }

    fn act(&self, observations: &[f32], skills: &[usize], actions: &mut [f32]) {
        let obs_dim = observations.len() / skills.len();
        let width = obs_dim + self.k;
        let mut inputs = vec![0.0; skills.len() * width];
        for ((obs, &k), row) in observations
            .chunks(obs_dim)
            .zip(skills)
            .zip(inputs.chunks_mut(width))
        {
            policy_input(obs, k, row);
        }
        actions.copy_from_slice(&self.sac.act(&inputs, None));
    }
}

impl AgentPolicy {
    /// Actions for rows of observations, row i executing skill `skills[i]`: deterministic when
    /// `rng` is `None`, else sampled with noise from `rng` (as training collects episodes).
    pub fn actions(
        &self,
        observations: &[f32],
        skills: &[usize],
        rng: Option<&mut rand_chacha::ChaCha8Rng>,
    ) -> Vec<f32> {
        let obs_dim = observations.len() / skills.len().max(1);
        let width = obs_dim + self.k;
        let mut inputs = vec![0.0; skills.len() * width];
        for ((obs, &k), row) in observations
            .chunks(obs_dim.max(1))
            .zip(skills)
            .zip(inputs.chunks_mut(width))
        {
            policy_input(obs, k, row);
        }
        self.sac.act(&inputs, rng)
    }
}

/// A trained SEADS agent.
pub struct Agent {
    /// The run's configuration.
    pub config: TrainConfig,
    /// The environment's dimensions.
    pub spec: EnvSpec,
    /// The checkpoint loaded.
    pub checkpoint: PathBuf,
    /// Epoch of the checkpoint.
    pub epoch: u64,
    /// The skill policy.
    pub policy: AgentPolicy,
    /// The agent's own forward model (SEADS's: the paper's or the mixture); `None` for a learner
    /// that learns none (VIC, DIAYN), whose skills are planned with a model fitted to them
    /// ([`Agent::fitted_model`]).
    pub model: Option<Box<dyn PlanningModel>>,
}

/// The checkpoint of epoch `epoch` of the run in `dir`, or its latest.
pub fn find_checkpoint(dir: &Path, epoch: Option<u64>) -> Result<PathBuf, RlError> {
    match epoch {
        Some(e) => checkpoints(dir)?
            .into_iter()
            .find(|(ce, _)| *ce == e)
            .map(|(_, p)| p)
            .ok_or_else(|| {
                RlError::from(seads_run::RunError::Checkpoint {
                    path: dir.display().to_string(),
                    reason: format!("no checkpoint of epoch {e}"),
                })
            }),
        None => latest_checkpoint(dir)?.ok_or_else(|| {
            RlError::from(seads_run::RunError::Checkpoint {
                path: dir.display().to_string(),
                reason: "the run has no checkpoint yet".into(),
            })
        }),
    }
}

impl Agent {
    /// Loads the latest checkpoint of the run in `dir`, or the one of epoch `epoch`.
    pub fn load(dir: &Path, epoch: Option<u64>) -> Result<Self, RlError> {
        let config = load_config(dir)?;
        Self::load_checkpoint(config, &find_checkpoint(dir, epoch)?)
    }

    /// Loads the agent saved in `checkpoint` by a run with `config`.
    pub fn load_checkpoint(config: TrainConfig, checkpoint: &Path) -> Result<Self, RlError> {
        let spec = make_env(&config.env, &config.env_config)?.spec().clone();
        Self::load_for(config, spec, checkpoint)
    }

    /// Loads the agent saved in `checkpoint` for an environment of `spec` (also one outside the
    /// registry, such as the robot).
    pub fn load_for(
        config: TrainConfig,
        spec: EnvSpec,
        checkpoint: &Path,
    ) -> Result<Self, RlError> {
        crate::numerics::check(config.portable_numerics)?;
        crate::store::check_origin(checkpoint, &config)?;
        // The agent as it was trained: a config.toml edited since (an environment setting, a
        // network size) would evaluate another agent than the one trained, so it is refused as
        // a resume refuses it.
        crate::store::check_config(checkpoint, &config)?;
        if config.baseline_training().is_ok() {
            return Err(RlError::config(format!(
                "a {} run learns a task policy, not skills",
                config.algorithm()
            )));
        }
        // Any skill learner: SAC's actor over [observation, one-hot skill]; SEADS also keeps
        // its forward model in the checkpoint.
        let k = config
            .learner
            .stated_num_skills()
            .unwrap_or(spec.num_skills);
        let device = config.device.resolve()?;
        let mut sac = Sac::new(
            spec.obs_dim + k,
            &spec.action_low,
            &spec.action_high,
            &config.sac,
            device,
            0,
        );
        sac.load(checkpoint, true)?;
        let own_model = if config.is::<SeadsConfig>() {
            Some(config.seads()?.skill_model)
        } else {
            None
        };
        let model: Option<Box<dyn PlanningModel>> = match own_model {
            Some(settings) if settings.kind == SkillModelKind::Forward => {
                let mut model = ForwardModel::new(spec.symbolic_len, k, &settings, device, 0);
                model.load(checkpoint, false)?;
                Some(Box::new(model))
            }
            Some(settings) if settings.kind == SkillModelKind::Mixture => {
                let mut model = MixtureModel::new(spec.symbolic_len, k, &settings, device, 0);
                model.load(checkpoint, false)?;
                Some(Box::new(model))
            }
            _ => None,
        };
        let epoch = checkpoint
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(crate::store::checkpoint_epoch)
            .ok_or_else(|| {
                RlError::from(seads_run::RunError::Checkpoint {
                    path: checkpoint.display().to_string(),
                    reason: "a checkpoint folder is named epoch-N".into(),
                })
            })?;
        Ok(Self {
            config,
            spec,
            checkpoint: checkpoint.to_path_buf(),
            epoch,
            policy: AgentPolicy { sac, k },
            model,
        })
    }

    /// The policy and the forward model, borrowed together (planning executes with one and
    /// searches with the other). Errors for an agent without a forward model.
    pub fn parts(&mut self) -> Result<(&AgentPolicy, &mut dyn Successor), RlError> {
        match &mut self.model {
            Some(model) => Ok((&self.policy, model.as_mut())),
            None => Err(RlError::config(format!(
                "this {} agent learned no forward model to plan with; fit one to its skills \
                 (`seads fit-model`) and plan with that",
                self.config.algorithm()
            ))),
        }
    }

    /// Skills K: the width of the policy's one-hot skill input.
    pub fn num_skills(&self) -> usize {
        self.policy.k
    }

    /// The forward model fitted to this agent's skills (`seads fit-model`) in the run
    /// directory `run`, with its record. Errors if the run has none, or if it was fitted to
    /// another checkpoint's skills.
    pub fn fitted_model(&self, run: &Path) -> Result<(ForwardModel, FitRecord), RlError> {
        let dir = fitted_model_dir(run);
        let record = read_fit_record(run)?.ok_or_else(|| {
            RlError::config(format!(
                "{} has no fitted model: fit one first (`seads fit-model --run {}`)",
                run.display(),
                run.display()
            ))
        })?;
        if record.checkpoint.epoch != self.epoch || record.num_skills != self.policy.k {
            return Err(RlError::config(format!(
                "{}'s fitted model was fitted to the {} skills of epoch {}, not to the {} of \
                 epoch {} evaluated: fit it again (`seads fit-model --refit`)",
                run.display(),
                record.num_skills,
                record.checkpoint.epoch,
                self.policy.k,
                self.epoch
            )));
        }
        let device = self.config.device.resolve()?;
        let mut model = ForwardModel::new(
            self.spec.symbolic_len,
            record.num_skills,
            &record.skill_model,
            device,
            0,
        );
        model.load(&dir, false)?;
        Ok((model, record))
    }
}

/// The policy saved in a checkpoint folder of a baseline run with `config` (only the actors are
/// read: older checkpoints keep nothing else).
pub fn load_policy(
    config: &TrainConfig,
    checkpoint: &Path,
) -> Result<Box<dyn TaskPolicy>, RlError> {
    crate::store::check_origin(checkpoint, config)?;
    let spec = make_env(&config.env, &config.env_config)?.spec().clone();
    crate::with_learner(
        config.algorithm(),
        LoadPolicy {
            config,
            spec: &spec,
            checkpoint,
        },
    )?
}

/// [`load_policy`]'s work with the run's learner.
struct LoadPolicy<'a> {
    config: &'a TrainConfig,
    spec: &'a EnvSpec,
    checkpoint: &'a Path,
}

impl WithLearner for LoadPolicy<'_> {
    type Output = Result<Box<dyn TaskPolicy>, RlError>;
    fn run<L: InWords + Send>(self) -> Self::Output {
        L::load_task_policy(self.config, self.spec, self.checkpoint)
    }
}
