//! The intrinsic reward of SEADS (SPEC §3.5): how well the final label explains the episode's
//! effect on the board, relative to the runner-up skill, plus a novelty bonus.

pub use seads_run::{Normalisation, RewardConfig};

/// The reward of an episode that did not change the board: −2·log K, for every label.
pub fn minimum_reward(k: usize) -> f32 {
    -2.0 * (k as f32).ln()
}

/// log q(k | z_0, z_T) = ℓ_k − logsumexp ℓ (uniform skill prior).
pub fn skill_log_posterior(scores: &[f32]) -> Vec<f32> {
    let max = scores.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let lse = max + scores.iter().map(|s| (s - max).exp()).sum::<f32>().ln();
    scores.iter().map(|s| s - lse).collect()
}

/// The clipped log-posterior C_k = max(log q(k | z_0, z_T), −2·log K) (relabelling's input).
///
/// ```
/// use seads_skillmodel::clipped_log_posterior;
/// // Two skills that explain the episode equally: log ½ each.
/// let c = clipped_log_posterior(&[-3.0, -3.0]);
/// assert!((c[0] - 0.5f32.ln()).abs() < 1e-6 && c[0] == c[1]);
/// // A skill far less likely than the best is clipped at −2·log K (K = 4: −2.7726).
/// let c = clipped_log_posterior(&[0.0, -20.0, -20.0, -20.0]);
/// assert!(c[0] > -1e-6);
/// assert!((c[1] - (-2.0 * 4f32.ln())).abs() < 1e-6 && c[1] == c[3]);
/// ```
pub fn clipped_log_posterior(scores: &[f32]) -> Vec<f32> {
    let floor = minimum_reward(scores.len());
    skill_log_posterior(scores)
        .into_iter()
        .map(|c| c.max(floor))
        .collect()
}

/// The second-largest value (the largest if there is only one).
pub fn second_best_normalisation(clipped: &[f32]) -> f32 {
    let (mut first, mut second) = (f32::NEG_INFINITY, f32::NEG_INFINITY);
    for &c in clipped {
        if c > first {
            second = first;
            first = c;
        } else if c > second {
            second = c;
        }
    }
    if second == f32::NEG_INFINITY {
        first
    } else {
        second
    }
}

/// n = min(−max_k ℓ_k, log K): large when no skill's forward model explains the transition.
pub fn novelty_bonus(likelihoods: &[f32]) -> f32 {
    let k = likelihoods.len() as f32;
    let best = likelihoods
        .iter()
        .copied()
        .fold(f32::NEG_INFINITY, f32::max);
    (-best).min(k.ln())
}

/// The clipped log-posterior C (K values) and the reward R_k of every label k (K values) for one
/// episode whose board changed, from its skill-model scores. `likelihoods` says whether the
/// scores are log q(z_T | z_0, k) (forward model), for which the novelty bonus is defined.
pub fn episode_rewards(
    scores: &[f32],
    likelihoods: bool,
    config: &RewardConfig,
) -> (Vec<f32>, Vec<f32>) {
    let clipped = clipped_log_posterior(scores);
    let k = scores.len() as f32;
    let offset = match config.normalisation {
        Normalisation::SecondBest => -second_best_normalisation(&clipped),
        Normalisation::LogK => k.ln(),
        Normalisation::None => 0.0,
    };
    let bonus = if config.novelty_bonus && likelihoods {
        novelty_bonus(scores)
    } else {
        0.0
    };
    let rewards = clipped.iter().map(|c| c + offset + bonus).collect();
    (clipped, rewards)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() < 1e-5
    }

    /// Hand computation with K = 3 and scores ℓ = (−1, −2, −30):
    /// logsumexp = −1 + ln(1 + e^−1 + e^−29) = −0.686738; posterior (−0.313262, −1.313262, −29.313262);
    /// clip at −2 ln 3 = −2.197225; second best = −1.313262; novelty = min(1, ln 3) = 1.
    #[test]
    fn rewards_by_hand() {
        let (c, r) = episode_rewards(&[-1.0, -2.0, -30.0], true, &RewardConfig::default());
        let expected_c = [-0.313262, -1.313262, -2.197225];
        let expected_r = [-0.313262 + 1.313262 + 1.0, 1.0, -2.197225 + 1.313262 + 1.0];
        for i in 0..3 {
            assert!(close(c[i], expected_c[i]), "C {c:?}");
            assert!(close(r[i], expected_r[i]), "R {r:?}");
        }
        // The most likely skill earns its margin over the runner-up (≥ 0), the others ≤ 0 (+ n).
        assert!(r[0] - 1.0 >= 0.0 && r[1] - 1.0 <= 0.0);
    }

    #[test]
    fn novelty_is_capped_at_log_k() {
        assert!(close(
            novelty_bonus(&[-50.0, -60.0, -70.0, -80.0]),
            4f32.ln()
        ));
        assert!(close(novelty_bonus(&[-0.5, -3.0]), 0.5));
        assert!(close(novelty_bonus(&[0.0, -3.0]), 0.0));
    }

    #[test]
    fn ablations_change_only_their_term() {
        let scores = [-1.0, -2.0, -30.0];
        let (_, no_sbn) = episode_rewards(
            &scores,
            true,
            &RewardConfig {
                normalisation: Normalisation::LogK,
                novelty_bonus: true,
            },
        );
        assert!(close(no_sbn[0], -0.313262 + 3f32.ln() + 1.0));
        let (_, no_nov) = episode_rewards(
            &scores,
            true,
            &RewardConfig {
                novelty_bonus: false,
                ..RewardConfig::default()
            },
        );
        assert!(close(no_nov[0], -0.313262 + 1.313262));
        // A discriminator's scores are not likelihoods: no novelty bonus whatever the switch.
        // By hand: logsumexp(−0.1, −2.4) = −0.0044545, posterior (−0.0955455, −2.3955455), the
        // runner-up clipped to −2 ln 2 = −1.3862944, so R_0 = 1.2907489. A bonus
        // min(0.1, ln 2) = 0.1 wrongly added would give 1.3907489.
        let (_, vic) = episode_rewards(&[-0.1, -2.4], false, &RewardConfig::default());
        assert!(close(vic[0], 1.290_749), "{}", vic[0]);
    }

    #[test]
    fn ranges_hold_for_k_25() {
        assert!(close(minimum_reward(25), -6.437752));
        assert!(close(minimum_reward(12), -4.969813));
        for scores in [[-0.01f32; 25], [-500.0; 25]] {
            let (_, r) = episode_rewards(&scores, true, &RewardConfig::default());
            for v in r {
                assert!((-2.0 * 25f32.ln()..=3.0 * 25f32.ln()).contains(&v), "{v}");
            }
        }
    }
}
