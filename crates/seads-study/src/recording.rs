//! Recording episodes (`seads record`, `docs/EPISODES.md`): random actions or an agent's
//! skills, one JSON line per episode.

use std::io::Write;

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use seads_embodiment::{Environment, SkillPolicy, record_episode};

use crate::{Context as _, Result};

/// Records `episodes` episodes of `steps` steps on `env` (registered as `name`) into `out`: uniformly random actions
/// drawn from `rng` without a `policy`, else the policy's skills in turn (episode i runs skill
/// i mod K). Each episode is written as soon as it ends.
pub fn record_episodes(
    env: &mut dyn Environment,
    name: &str,
    policy: Option<&dyn SkillPolicy>,
    episodes: usize,
    steps: usize,
    rng: &mut ChaCha8Rng,
    out: &mut impl Write,
) -> Result<()> {
    let (low, high) = (
        env.spec().action_low.clone(),
        env.spec().action_high.clone(),
    );
    for i in 0..episodes {
        let mut episode = match policy {
            None => record_episode(env, steps, |_, action| {
                for (a, (l, h)) in action.iter_mut().zip(low.iter().zip(&high)) {
                    *a = rng.random_range(*l..=*h);
                }
            })
            .doing(|| format!("recording episode {i}"))?,
            Some(policy) => {
                let skill = i % policy.num_skills();
                let mut episode =
                    record_episode(env, steps, |obs, action| policy.act(obs, &[skill], action))
                        .doing(|| format!("recording episode {i}"))?;
                episode.skill = Some(skill);
                episode
            }
        };
        episode.env = name.to_owned();
        let line = serde_json::to_string(&episode).doing(|| "encoding an episode".to_owned())?;
        writeln!(out, "{line}").doing(|| "writing an episode".to_owned())?;
    }
    Ok(())
}
