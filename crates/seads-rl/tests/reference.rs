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
        updates_per_epoch: 1,
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
