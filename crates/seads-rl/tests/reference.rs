//! SAC against PyTorch: one update from stored weights, batch and noise gives PyTorch's losses and
//! updated parameters (data/reference/sac_update.safetensors, written by
//! scripts/reference/sac_update.py with torch.nn and torch.optim.Adam).

use std::path::Path;

use seads_rl::{Sac, SacConfig, TransitionBatch};
use tch::{Device, Tensor};

fn reference() -> Vec<(String, Tensor)> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/reference/sac_update.safetensors");
    Tensor::read_safetensors(path).unwrap()
}

fn get<'a>(tensors: &'a [(String, Tensor)], name: &str) -> &'a Tensor {
    &tensors
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("{name}"))
        .1
}

fn floats(t: &Tensor) -> Vec<f32> {
    Vec::<f32>::try_from(t.view([-1])).unwrap()
}

/// Writes the tensors named `<store>.*` as the checkpoint file `<store>.safetensors`.
fn write_store(tensors: &[(String, Tensor)], prefix: &str, store: &str, dir: &Path) {
    let part: Vec<(String, Tensor)> = tensors
        .iter()
        .filter_map(|(n, t)| {
            n.strip_prefix(&format!("{prefix}{store}."))
                .map(|rest| (rest.to_owned(), t.shallow_clone()))
        })
        .collect();
    assert!(!part.is_empty(), "{prefix}{store}");
    Tensor::write_safetensors(&part, dir.join(format!("{store}.safetensors"))).unwrap();
}

#[test]
fn one_update_matches_pytorch() {
    let data = reference();
    let config = SacConfig {
        hidden: vec![8, 8],
        lr: 1e-2,
        gamma: 0.99,
        tau: 0.005,
        alpha: 0.1,
        batch_size: 5,
    };
    let mut sac = Sac::new(7, &[-1.0, -2.0], &[1.0, 3.0], &config, Device::Cpu, 0);
    // A fresh optimiser state from our own save, the networks from PyTorch.
    let dir = tempfile::tempdir().unwrap();
    sac.save(dir.path()).unwrap();
    for store in ["sac_actor", "sac_critic", "sac_target"] {
        write_store(&data, "", store, dir.path());
    }
    sac.load(dir.path(), false).unwrap();
    let input = |name: &str| floats(get(&data, &format!("input.{name}")));
    let batch = TransitionBatch {
        obs: input("obs"),
        actions: input("actions"),
        rewards: input("rewards"),
        next_obs: input("next_obs"),
        dones: input("dones"),
    };
    let losses = sac.update_with_noise(
        &batch,
        get(&data, "input.next_noise"),
        get(&data, "input.policy_noise"),
    );
    let expected = floats(get(&data, "expected.losses"));
    let ours = [losses.critic, losses.actor, losses.q];
    for (name, (a, b)) in ["critic loss", "actor loss", "mean min-Q"]
        .iter()
        .zip(ours.iter().zip(&expected))
    {
        assert!(
            (a - b).abs() <= 1e-5 * (1.0 + b.abs()),
            "{name}: {a} vs PyTorch {b}"
        );
    }
    // The updated networks, parameter by parameter.
    let after = tempfile::tempdir().unwrap();
    sac.save(after.path()).unwrap();
    let mut compared = 0;
    for store in ["sac_actor", "sac_critic", "sac_target"] {
        let ours =
            Tensor::read_safetensors(after.path().join(format!("{store}.safetensors"))).unwrap();
        for (name, tensor) in &ours {
            let theirs = floats(get(&data, &format!("expected.{store}.{name}")));
            let before = floats(get(&data, &format!("{store}.{name}")));
            let mine = floats(tensor);
            assert_eq!(mine.len(), theirs.len(), "{store}.{name}");
            for i in 0..mine.len() {
                assert!(
                    (mine[i] - theirs[i]).abs() <= 2e-6,
                    "{store}.{name}[{i}]: {} vs PyTorch {} (before {})",
                    mine[i],
                    theirs[i],
                    before[i]
                );
            }
            // The update moved every trained parameter, so the comparison has teeth.
            if store != "sac_target" {
                assert!(
                    mine.iter().zip(&before).any(|(a, b)| a != b),
                    "{store}.{name} moved"
                );
            }
            compared += 1;
        }
    }
    assert_eq!(compared, 8 + 12 + 12);
}

/// RelaxedBernoulli (HAC's subgoal policy) against torch.distributions.RelaxedBernoulli:
/// reparameterised samples from the same uniforms, their gradient in the logits, and
/// log-densities (data/reference/relaxed_bernoulli.safetensors, written by
/// scripts/reference/relaxed_bernoulli.py).
#[test]
fn relaxed_bernoulli_matches_pytorch() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/reference/relaxed_bernoulli.safetensors");
    let data = Tensor::read_safetensors(path).unwrap();
    let close = |ours: &Tensor, theirs: &Tensor, what: &str, tol: f32| {
        let (a, b) = (floats(ours), floats(theirs));
        assert_eq!(a.len(), b.len(), "{what}");
        for (i, (x, y)) in a.iter().zip(&b).enumerate() {
            assert!(
                (x - y).abs() <= tol * (1.0 + y.abs()),
                "{what}[{i}]: {x} against PyTorch's {y}"
            );
        }
    };
    for (name, temperature) in [("t01", 0.1), ("t05", 0.5)] {
        let logits = get(&data, "logits").copy().set_requires_grad(true);
        let dist = seads_rl::RelaxedBernoulli::new(temperature, logits.shallow_clone());
        let sample = dist.rsample_with(get(&data, &format!("{name}.uniforms")));
        close(
            &sample,
            get(&data, &format!("{name}.sample")),
            &format!("{name} sample"),
            1e-5,
        );
        sample.sum(tch::Kind::Float).backward();
        close(
            &logits.grad(),
            get(&data, &format!("{name}.sample_grad")),
            &format!("{name} d sample / d logits"),
            1e-4,
        );
        let at_sample = dist.log_prob(&get(&data, &format!("{name}.sample")).detach());
        close(
            &at_sample.detach(),
            get(&data, &format!("{name}.log_prob_sample")),
            &format!("{name} log-density at the samples"),
            1e-4,
        );
        let at_values = dist.log_prob(get(&data, "values"));
        close(
            &at_values.detach(),
            get(&data, &format!("{name}.log_prob_values")),
            &format!("{name} log-density at fixed values"),
            1e-5,
        );
        // The deterministic action thresholds the probability at 0.5.
        assert_eq!(
            floats(&dist.mode()),
            floats(&get(&data, "logits").gt(0.0).to_kind(tch::Kind::Float))
        );
    }
}
