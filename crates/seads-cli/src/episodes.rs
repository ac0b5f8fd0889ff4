//! `seads record` and `seads replay`: episodes as JSON Lines (`docs/EPISODES.md`).

use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Args;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{
    EnvConfig, EpisodeRecord, SkillPolicy, compare, record_episode, replay_episode,
};

use crate::BadInput;
use crate::envs::build_env;

/// Arguments of `seads record`.
#[derive(Debug, Args)]
pub struct RecordArgs {
    /// Environment name (see `seads envs`).
    #[arg(long)]
    env: String,
    /// Episodes to record.
    #[arg(long, default_value_t = 10)]
    episodes: usize,
    /// Steps per episode (no step limit, no reset after a move).
    #[arg(long, default_value_t = 100)]
    steps: usize,
    /// `random` (uniform actions) or the run directory of a trained agent (episode i executes
    /// skill i mod K deterministically).
    #[arg(long, default_value = "random")]
    policy: String,
    /// Seed of the resets and of the random actions.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output file (JSON Lines).
    #[arg(long)]
    out: PathBuf,
}

/// `seads record`.
pub fn record(args: RecordArgs) -> Result<()> {
    let mut env = build_env(&args.env, &EnvConfig::default())?;
    let agent = match args.policy.as_str() {
        "random" => None,
        dir => {
            let agent = crate::plan::load_agent(
                std::path::Path::new(dir),
                None,
                seads_rl::ComputeDevice::Cpu,
            )?;
            if agent.config.env != args.env {
                bail!(BadInput(anyhow::anyhow!(
                    "the agent in {dir} was trained on {}, not {}",
                    agent.config.env,
                    args.env
                )));
            }
            Some(agent)
        }
    };
    // One episode is held in memory (its steps and its JSON line) before it is written.
    let spec = env.spec();
    let episode_bytes = args.steps as f64 * (spec.obs_dim + spec.action_dim) as f64 * 24.0;
    let memory = seads_rl::machine_memory_bytes();
    if episode_bytes > memory as f64 {
        bail!(BadInput(anyhow::anyhow!(
            "--steps {} needs about {:.1} GiB per episode, more than this machine's {:.1} GiB",
            args.steps,
            episode_bytes / f64::from(1u32 << 30),
            memory as f64 / f64::from(1u32 << 30)
        )));
    }
    env.seed(args.seed);
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    // Written beside the output and renamed over it when complete: never a half-written file.
    let mut file = atomic_file(&args.out)?;
    write_episodes(&args, &mut file, env.as_mut(), agent.as_ref(), &mut rng)?;
    commit(file, &args.out)?;
    outln!(
        "recorded {} episodes of {} steps into {}",
        args.episodes,
        args.steps,
        args.out.display()
    );
    Ok(())
}

/// A file written beside `path` and renamed over it, synced, only by [`commit`]: dropped
/// without it (an error on the way), `path` stays as it was.
fn atomic_file(path: &std::path::Path) -> Result<BufWriter<atomic_write_file::AtomicWriteFile>> {
    let file = atomic_write_file::AtomicWriteFile::open(path)
        .with_context(|| format!("creating {}", path.display()))?;
    Ok(BufWriter::new(file))
}

/// Puts what [`atomic_file`] wrote in place of `path`.
fn commit(
    out: BufWriter<atomic_write_file::AtomicWriteFile>,
    path: &std::path::Path,
) -> Result<()> {
    out.into_inner()
        .map_err(|e| e.into_error())
        .and_then(|file| file.commit())
        .with_context(|| format!("writing {}", path.display()))
}

/// Records the episodes of `args` into `out`.
fn write_episodes(
    args: &RecordArgs,
    out: &mut impl Write,
    env: &mut dyn seads_embodiment::Environment,
    agent: Option<&seads_rl::Agent>,
    rng: &mut ChaCha8Rng,
) -> Result<()> {
    let (low, high) = (
        env.spec().action_low.clone(),
        env.spec().action_high.clone(),
    );
    for i in 0..args.episodes {
        let mut episode = match &agent {
            None => record_episode(env, args.steps, |_, action| {
                for (a, (l, h)) in action.iter_mut().zip(low.iter().zip(&high)) {
                    *a = rng.random_range(*l..=*h);
                }
            })?,
            Some(agent) => {
                let skill = i % agent.policy.num_skills();
                let mut episode = record_episode(env, args.steps, |obs, action| {
                    agent.policy.act(obs, &[skill], action)
                })?;
                episode.skill = Some(skill);
                episode
            }
        };
        episode.env = args.env.clone();
        writeln!(out, "{}", serde_json::to_string(&episode)?)
            .with_context(|| format!("writing {}", args.out.display()))?;
    }
    Ok(())
}

/// Arguments of `seads replay`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// Environment name; every episode of the input must be of it.
    #[arg(long)]
    env: String,
    /// Episodes to replay (JSON Lines, `docs/EPISODES.md`).
    #[arg(long)]
    input: PathBuf,
    /// Where to write the replayed episodes (observations and moves recomputed).
    #[arg(long)]
    out: PathBuf,
    /// Print, per episode, how the replay differs from the input; exit non-zero if a board
    /// differs.
    #[arg(long)]
    compare: bool,
}

/// `seads replay`.
pub fn replay(args: ReplayArgs) -> Result<()> {
    crate::refuse_overwriting_input(&args.out, &[&args.input])?;
    let mut env = build_env(&args.env, &EnvConfig::default())?;
    let m = env.spec().manipulator_dim;
    let input = std::fs::File::open(&args.input)
        .with_context(|| format!("opening {}", args.input.display()))?;
    // Written beside the output and renamed over it when every line is replayed.
    let mut out = atomic_file(&args.out)?;
    let (mut episodes, mut differing) = (0, 0);
    for (number, line) in BufReader::new(input).lines().enumerate() {
        let line = line.with_context(|| format!("reading {}", args.input.display()))?;
        if line.trim().is_empty() {
            continue;
        }
        let at = || format!("{}:{}", args.input.display(), number + 1);
        let record: EpisodeRecord = serde_json::from_str(&line)
            .map_err(|e| BadInput(anyhow::anyhow!("{}: not an episode: {e}", at())))?;
        let replayed = replay_episode(env.as_mut(), &record)
            .map_err(|e| BadInput(anyhow::anyhow!("{}: {e}", at())))?;
        writeln!(out, "{}", serde_json::to_string(&replayed)?)?;
        if args.compare {
            let c = compare(&record, &replayed, m);
            differing += (c.board_mismatches > 0) as usize;
            outln!(
                "episode {episodes} (line {}): {} steps, max manipulator deviation {:.3e}, {} board and {} move mismatches",
                number + 1,
                c.steps,
                c.max_manipulator_deviation,
                c.board_mismatches,
                c.move_mismatches
            );
        }
        episodes += 1;
    }
    commit(out, &args.out)?;
    if differing > 0 {
        bail!("the board differs from the recording in {differing} of {episodes} episodes");
    }
    if !args.compare {
        outln!("replayed {episodes} episodes into {}", args.out.display());
    }
    Ok(())
}
