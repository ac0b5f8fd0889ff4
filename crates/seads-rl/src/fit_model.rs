//! Fitting SEADS's forward model to any trained learner's frozen skills (`seads fit-model`), so
//! that skills learned without a model (DIAYN, VIC) can be planned with, and learners compare by
//! their skills alone.
//!
//! The skills are executed as evaluations execute them (deterministically), each from a fresh
//! reset of a training board with a skill drawn uniformly, as SEADS collects its own episodes;
//! the model is SEADS's (the environment's preset `[seads.skill_model]`), trained on the
//! observed (z_0, k, z_T) by its own loss. One execution in [`FitSettings::HELD_OUT_EVERY`] is
//! held out to measure the fit ([`FitQuality`]).

use std::path::Path;

use seads_nn::Resolve as _;

use rand::RngExt;
use seads_embodiment::{EnvConfig, Environment, make_env};
use seads_games::{Split, Successor, SymbolicState};
use seads_planner::Evaluator;
use seads_run::fitted::{FIT_RECORD, FitQuality, FitRecord, FitSettings, fitted_model_dir};
use seads_run::store::{checkpoint_id, commit_dir, hidden_sibling, write_atomic};
use seads_skillmodel::{ForwardModel, SkillModel, SkillModelConfig, SkillTransition};

use crate::episode::run_episodes;
use crate::seeds::{Purpose, derived_seed, stream};
use crate::{Agent, RlError, SeadsConfig, TrainConfig};

/// Skill executions stepped together (one batched policy call per time step).
const ROUND: usize = 64;

/// Where a fit is, for progress: executions collected, then gradient steps taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FitProgress {
    /// `done` of `total` executions collected.
    Collecting {
        /// Collected so far.
        done: usize,
        /// To collect.
        total: usize,
    },
    /// `done` of `total` gradient steps taken.
    Training {
        /// Taken so far.
        done: usize,
        /// To take.
        total: usize,
    },
}

/// The forward model's settings for a run's environment: those of the environment's SEADS
/// preset (a SEADS run's own where it trained one), so that every learner is fitted alike.
pub fn fit_settings_of(config: &TrainConfig) -> Result<SkillModelConfig, RlError> {
    let preset = TrainConfig::preset_for(&config.env, "seads")?;
    let mut settings = preset.section::<SeadsConfig>()?.skill_model;
    settings.kind = seads_skillmodel::SkillModelKind::Forward;
    Ok(settings)
}

/// Executes `agent`'s skills as `settings` say and returns the executions as transitions, in
/// the order drawn.
pub fn collect_transitions(
    agent: &Agent,
    settings: &FitSettings,
    mut progress: impl FnMut(FitProgress),
) -> Result<Vec<SkillTransition>, RlError> {
    let config = &agent.config;
    let template = make_env(
        &config.env,
        &EnvConfig {
            reset_split: Split::Train,
            ..config.env_config.clone()
        },
    )?;
    let k = agent.num_skills();
    let mut skills_stream = stream(settings.seed, Purpose::FitSkills);
    let mut transitions = Vec::with_capacity(settings.episodes);
    while transitions.len() < settings.episodes {
        let start = transitions.len();
        let n = ROUND.min(settings.episodes - start);
        let mut envs: Vec<Box<dyn Environment>> = Vec::with_capacity(n);
        for i in start..start + n {
            let mut env = template.box_clone();
            env.seed(derived_seed(settings.seed, Purpose::FitBoards, i as u64));
            env.reset()?;
            envs.push(env);
        }
        let skills: Vec<usize> = (0..n).map(|_| skills_stream.random_range(0..k)).collect();
        let episodes = run_episodes(&mut envs, &skills, &agent.policy.sac, k, None)?;
        transitions.extend(episodes.iter().map(|e| SkillTransition {
            z0: e.z0,
            skill: e.skill,
            zt: e.zt,
        }));
        progress(FitProgress::Collecting {
            done: transitions.len(),
            total: settings.episodes,
        });
    }
    Ok(transitions)
}

/// Trains a fresh forward model on the executions not held out and measures it on the others.
pub fn train_model(
    transitions: &[SkillTransition],
    symbolic_len: usize,
    num_skills: usize,
    skill_model: &SkillModelConfig,
    settings: &FitSettings,
    device: tch::Device,
    mut progress: impl FnMut(FitProgress),
) -> Result<(ForwardModel, FitQuality), RlError> {
    settings.validate()?;
    let every = FitSettings::HELD_OUT_EVERY;
    let (mut train, mut held_out) = (Vec::new(), Vec::new());
    for (i, t) in transitions.iter().enumerate() {
        if i % every == every - 1 {
            held_out.push(*t);
        } else {
            train.push(*t);
        }
    }
    if train.is_empty() || held_out.is_empty() {
        return Err(RlError::config(format!(
            "a fit needs at least {every} skill executions, not {}",
            transitions.len()
        )));
    }
    let mut model = ForwardModel::new(
        symbolic_len,
        num_skills,
        skill_model,
        device,
        derived_seed(settings.seed, Purpose::FitInit, 0),
    );
    let mut batches = stream(settings.seed, Purpose::FitBatches);
    let mut batch = Vec::with_capacity(skill_model.batch_size);
    for step in 0..settings.updates {
        batch.clear();
        batch.extend(
            (0..skill_model.batch_size).map(|_| train[batches.random_range(0..train.len())]),
        );
        model.train_step(&batch);
        if (step + 1) % 100 == 0 || step + 1 == settings.updates {
            progress(FitProgress::Training {
                done: step + 1,
                total: settings.updates,
            });
        }
    }
    let quality = measure(&mut model, &held_out, transitions);
    Ok((model, quality))
}

/// The fit's quality on `held_out` (and the share of `all` that changed the board).
fn measure(
    model: &mut ForwardModel,
    held_out: &[SkillTransition],
    all: &[SkillTransition],
) -> FitQuality {
    let k = SkillModel::num_skills(model);
    let pairs: Vec<(SymbolicState, SymbolicState)> =
        held_out.iter().map(|t| (t.z0, t.zt)).collect();
    let scores = model.scores(&pairs);
    let log_likelihood = held_out
        .iter()
        .enumerate()
        .map(|(i, t)| f64::from(scores[i * k + t.skill]))
        .sum::<f64>()
        / held_out.len() as f64;
    let starts: Vec<SymbolicState> = held_out.iter().map(|t| t.z0).collect();
    let mut predicted = Vec::new();
    model.successors(&starts, &mut predicted);
    let hits = held_out
        .iter()
        .enumerate()
        .filter(|&(i, t)| predicted[i * k + t.skill] == t.zt)
        .count();
    FitQuality {
        held_out: held_out.len(),
        log_likelihood,
        mode_accuracy: hits as f64 / held_out.len() as f64,
        changed: all.iter().filter(|t| t.z0 != t.zt).count() as f64 / all.len() as f64,
    }
}

/// Fits a forward model to the skills of `agent` (loaded from the run directory `run`) and
/// writes it with its record into the run's `fitted-model` folder, replacing one there
/// (atomically: a crash leaves the old folder or the new). `fitted_by` names the binary.
pub fn fit_model(
    agent: &Agent,
    run: &Path,
    settings: &FitSettings,
    fitted_by: Vec<Evaluator>,
    mut progress: impl FnMut(FitProgress),
) -> Result<FitRecord, RlError> {
    settings.validate()?;
    let skill_model = fit_settings_of(&agent.config)?;
    let transitions = collect_transitions(agent, settings, &mut progress)?;
    let device = agent.config.device.resolve()?;
    let (model, quality) = train_model(
        &transitions,
        agent.spec.symbolic_len,
        agent.num_skills(),
        &skill_model,
        settings,
        device,
        &mut progress,
    )?;
    let checkpoint = checkpoint_id(run, &agent.checkpoint)?;
    let record = FitRecord {
        checkpoint,
        num_skills: agent.num_skills(),
        settings: *settings,
        skill_model,
        quality,
        fitted_by,
    };
    let dest = fitted_model_dir(run);
    let tmp = hidden_sibling(&dest, "tmp");
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp).map_err(|e| RlError::io(&tmp, e))?;
    }
    std::fs::create_dir_all(&tmp).map_err(|e| RlError::io(&tmp, e))?;
    SkillModel::save(&model, &tmp)?;
    let json = serde_json::to_string_pretty(&record).map_err(|e| RlError::io(&tmp, e))?;
    write_atomic(&tmp.join(FIT_RECORD), format!("{json}\n").as_bytes())?;
    commit_dir(&tmp, &dest)?;
    Ok(record)
}

#[cfg(test)]
mod tests {
    use seads_games::LightsOut;

    use super::*;

    /// The game's own moves as skills (skill k presses field k): a perfect fit predicts every
    /// held-out execution, and the mode accuracy says so; a model trained on nothing does not.
    fn moves_of(game: &LightsOut, n: usize, seed: u64) -> Vec<SkillTransition> {
        seads_skillmodel::move_transitions(game, n, &mut stream(seed, Purpose::FitBoards))
    }

    #[test]
    fn a_model_fitted_to_a_games_moves_predicts_the_held_out_ones() {
        let game = LightsOut::new(3).unwrap();
        let transitions = moves_of(&game, 2_000, 3);
        let config = SkillModelConfig {
            batch_size: 64,
            lr: 3e-3,
            hidden: vec![64],
            ..SkillModelConfig::default()
        };
        let fit = |updates| {
            let settings = FitSettings {
                episodes: transitions.len(),
                updates,
                seed: 5,
            };
            let noop = |_| {};
            train_model(
                &transitions,
                9,
                9,
                &config,
                &settings,
                tch::Device::Cpu,
                noop,
            )
            .unwrap()
            .1
        };
        let trained = fit(1_500);
        assert_eq!(trained.held_out, 200);
        assert!(trained.mode_accuracy > 0.95, "{trained:?}");
        // Every LightsOut move changes the board.
        assert_eq!(trained.changed, 1.0);
        // One step learns almost nothing: the measure can tell the difference.
        let untrained = fit(1);
        assert!(untrained.mode_accuracy < 0.2, "{untrained:?}");
        assert!(untrained.log_likelihood < trained.log_likelihood - 1.0);
        // The same settings fit the same model, to the bit.
        assert_eq!(fit(1_500), trained);
    }

    #[test]
    fn too_few_executions_are_refused() {
        let game = LightsOut::new(3).unwrap();
        let transitions = moves_of(&game, 5, 3);
        let settings = FitSettings {
            episodes: 5,
            updates: 10,
            seed: 1,
        };
        let result = train_model(
            &transitions,
            9,
            9,
            &SkillModelConfig::default(),
            &settings,
            tch::Device::Cpu,
            |_| {},
        );
        assert!(matches!(
            result,
            Err(RlError::Run(seads_run::RunError::Config(_)))
        ));
    }
}
