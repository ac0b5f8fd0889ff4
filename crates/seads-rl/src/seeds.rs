//! Random streams of a run: every random choice flows from the run's seed and a purpose.
//!
//! A stream is ChaCha8 keyed by the seed, with the purpose as its stream number, so two purposes
//! of one run never share numbers, and neither do two runs (seeding the skill model with
//! `seed + 1`, as this project once did, made run s's skill model draw what run s + 1's SAC drew).
//! ChaCha8 is specified bit for bit, so a seed gives the same numbers on every machine.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// What a random stream of a run is used for. The discriminant is the ChaCha8 stream number and
/// must never change: it fixes every run's numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u64)]
pub enum Purpose {
    /// Skill labels of new episodes.
    Labels = 1,
    /// Policy noise while collecting.
    Collect = 2,
    /// Buffer sampling, relabelling choices and minibatch picks.
    Sample = 3,
    /// SAC update noise.
    Sac = 4,
    /// Initial weights of the actor and the critics.
    SacInit = 5,
    /// Initial weights of the skill model (forward model or discriminator).
    SkillModelInit = 6,
    /// Seeds of the training environments, one per (epoch, episode slot).
    TrainEnvs = 7,
    /// A model fitted to frozen skills (`seads fit-model`): the seed of each execution's board.
    FitBoards = 8,
    /// … the skill each execution runs.
    FitSkills = 9,
    /// … the model's initial weights.
    FitInit = 10,
    /// … the executions each gradient step learns from.
    FitBatches = 11,
}

/// The stream of `purpose` in the run seeded with `seed`.
pub fn stream(seed: u64, purpose: Purpose) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(purpose as u64);
    rng
}

/// The `index`-th 64-bit value of the stream of `purpose`: a seed for something that is
/// re-seeded often (an environment per epoch), found without drawing the values before it.
///
/// ```
/// use rand::RngExt;
/// use seads_rl::{Purpose, derived_seed, stream};
/// // The same value as drawing the stream up to it.
/// let mut labels = stream(7, Purpose::Labels);
/// let drawn: Vec<u64> = (0..3).map(|_| labels.random()).collect();
/// assert_eq!(derived_seed(7, Purpose::Labels, 2), drawn[2]);
/// // Another purpose, or another run, has other numbers.
/// assert_ne!(derived_seed(7, Purpose::TrainEnvs, 2), drawn[2]);
/// assert_ne!(derived_seed(8, Purpose::Labels, 2), drawn[2]);
/// ```
pub fn derived_seed(seed: u64, purpose: Purpose, index: u64) -> u64 {
    let mut rng = stream(seed, purpose);
    // One u64 is two 32-bit words of the ChaCha block stream.
    rng.set_word_pos(u128::from(index) * 2);
    rng.next_u64()
}

/// The seed of training environment `slot` in epoch `epoch` of a run with `slots` episodes per
/// epoch. Environments are re-seeded before every epoch, so their state at an epoch depends on
/// nothing but (seed, epoch, slot): a resumed run collects exactly what the killed run would have.
pub fn train_env_seed(seed: u64, epoch: u64, slots: usize, slot: usize) -> u64 {
    derived_seed(
        seed,
        Purpose::TrainEnvs,
        epoch.wrapping_mul(slots as u64).wrapping_add(slot as u64),
    )
}

#[cfg(test)]
mod tests {
    use rand::Rng;

    use super::*;

    /// Golden values: the first numbers of two streams, recorded when the streams were fixed.
    /// They pin every run's numbers, so a change of rand_chacha, of `seed_from_u64` or of the
    /// purposes fails here instead of silently changing runs.
    #[test]
    fn streams_are_pinned() {
        let golden = [
            stream(1, Purpose::Labels).next_u64(),
            stream(1, Purpose::Collect).next_u64(),
            derived_seed(9, Purpose::TrainEnvs, 4),
        ];
        assert_eq!(
            golden,
            [
                15_715_005_604_373_573_095,
                16_166_618_085_559_792_950,
                7_539_574_757_970_048_457
            ]
        );
        let mut s = stream(9, Purpose::TrainEnvs);
        let values: Vec<u64> = (0..5).map(|_| s.next_u64()).collect();
        for (i, v) in values.iter().enumerate() {
            assert_eq!(derived_seed(9, Purpose::TrainEnvs, i as u64), *v);
        }
    }

    /// Run s's skill-model stream is not run s + 1's SAC stream (the reference's overlap), and no
    /// two purposes of neighbouring runs start alike.
    #[test]
    fn runs_and_purposes_do_not_share_streams() {
        let purposes = [
            Purpose::Labels,
            Purpose::Collect,
            Purpose::Sample,
            Purpose::Sac,
            Purpose::SacInit,
            Purpose::SkillModelInit,
            Purpose::TrainEnvs,
            Purpose::FitBoards,
            Purpose::FitSkills,
            Purpose::FitInit,
            Purpose::FitBatches,
        ];
        let mut firsts = Vec::new();
        for seed in 1..=5 {
            for p in purposes {
                let mut rng = stream(seed, p);
                firsts.push([rng.next_u64(), rng.next_u64()]);
            }
        }
        let n = firsts.len();
        firsts.sort_unstable();
        firsts.dedup();
        assert_eq!(firsts.len(), n, "two streams start with the same values");
    }

    #[test]
    fn environment_seeds_differ_per_epoch_and_slot() {
        let mut seeds: Vec<u64> = (0..50)
            .flat_map(|epoch| (0..32).map(move |slot| train_env_seed(3, epoch, 32, slot)))
            .collect();
        let n = seeds.len();
        seeds.sort_unstable();
        seeds.dedup();
        assert_eq!(seeds.len(), n);
        assert_eq!(
            train_env_seed(3, 7, 32, 5),
            derived_seed(3, Purpose::TrainEnvs, 7 * 32 + 5)
        );
    }
}
