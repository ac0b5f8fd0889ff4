//! `seads record` and `seads replay`: episodes as JSON Lines (`docs/EPISODES.md`).

use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Args;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{EnvConfig, EpisodeRecord, compare, replay_episode};

use crate::BadInput;
use crate::envs::build_env;
use seads_rl::store::AtomicFile;

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
    let policy_dir = std::path::Path::new(&args.policy);
    let inputs: Vec<&std::path::Path> = if agent.is_some() {
        vec![policy_dir]
    } else {
        Vec::new()
    };
    crate::paths::refuse_unsafe_output(&args.out, &inputs)?;
    env.seed(args.seed);
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    // Written beside the output and renamed over it when complete: never a half-written file.
    let mut file = AtomicFile::open(&args.out)?;
    let policy = agent
        .as_ref()
        .map(|a| &a.policy as &dyn seads_embodiment::SkillPolicy);
    let (episodes, steps) = (args.episodes, args.steps);
    seads_study::recording::record_episodes(
        env.as_mut(),
        &args.env,
        policy,
        episodes,
        steps,
        &mut rng,
        &mut file,
    )
    .with_context(|| format!("writing {}", args.out.display()))?;
    file.commit()?;
    outln!(
        "recorded {} episodes of {} steps into {}",
        args.episodes,
        args.steps,
        args.out.display()
    );
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
    crate::paths::refuse_unsafe_output(&args.out, &[&args.input])?;
    let mut env = build_env(&args.env, &EnvConfig::default())?;
    let m = env.spec().manipulator_dim;
    let input = std::fs::File::open(&args.input)
        .with_context(|| format!("opening {}", args.input.display()))?;
    // Written beside the output and renamed over it when every line is replayed.
    let mut out = AtomicFile::open(&args.out)?;
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
    out.commit()?;
    if differing > 0 {
        bail!("the board differs from the recording in {differing} of {episodes} episodes");
    }
    if !args.compare {
        outln!("replayed {episodes} episodes into {}", args.out.display());
    }
    Ok(())
}
