//! The forward model against PyTorch: log q(z_T | z_0, k) of a batch for every skill, the loss
//! of a labelled batch and the weights after one Adam step equal PyTorch's at the same weights and
//! inputs (data/reference/forward_model.safetensors, written by
//! scripts/reference/forward_model.py with torch.nn, torch.distributions.Bernoulli and
//! torch.optim.Adam).

use std::path::Path;

use seads_games::SymbolicState;
use seads_skillmodel::{ForwardModel, SkillModel, SkillModelConfig, SkillTransition};
use tch::{Device, Tensor};

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

/// Rows of 0/1 values as symbolic states (bit d = column d).
fn states(t: &Tensor, d: usize) -> Vec<SymbolicState> {
    floats(t)
        .chunks(d)
        .map(|row| {
            let bits = row
                .iter()
                .enumerate()
                .fold(0u64, |acc, (i, &v)| acc | (u64::from(v == 1.0) << i));
            SymbolicState::from_u64(bits)
        })
        .collect()
}

#[test]
fn log_likelihoods_loss_and_step_match_pytorch() {
    let (d, k) = (6, 3);
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/reference/forward_model.safetensors");
    let data = Tensor::read_safetensors(path).unwrap();
    let config = SkillModelConfig {
        hidden: vec![8, 8],
        lr: 1e-3,
        ..SkillModelConfig::default()
    };
    let mut model = ForwardModel::new(d, k, &config, Device::Cpu, 0);
    let dir = tempfile::tempdir().unwrap();
    model.save(dir.path()).unwrap();
    let weights: Vec<(String, Tensor)> = data
        .iter()
        .filter(|(n, _)| n.starts_with("forward_model."))
        .map(|(n, t)| (n.clone(), t.shallow_clone()))
        .collect();
    assert_eq!(weights.len(), 6);
    Tensor::write_safetensors(&weights, dir.path().join("forward_model.safetensors")).unwrap();
    model.load(dir.path(), true).unwrap();

    let z0 = states(get(&data, "input.z0"), d);
    let zt = states(get(&data, "input.zt"), d);
    let pairs: Vec<_> = z0.iter().copied().zip(zt.iter().copied()).collect();
    let scores = model.scores(&pairs);
    let expected = floats(get(&data, "expected.scores"));
    assert_eq!(scores.len(), expected.len());
    for (i, (a, b)) in scores.iter().zip(&expected).enumerate() {
        assert!(
            (a - b).abs() <= 1e-5 * (1.0 + b.abs()),
            "score {i}: {a} vs PyTorch {b}"
        );
    }

    let labels = floats(get(&data, "input.labels"));
    let batch: Vec<SkillTransition> = (0..z0.len())
        .map(|i| SkillTransition {
            z0: z0[i],
            skill: labels[i] as usize,
            zt: zt[i],
        })
        .collect();
    let loss = model.train_step(&batch);
    let expected_loss = floats(get(&data, "expected.loss"))[0];
    assert!(
        (loss - expected_loss).abs() <= 1e-6,
        "loss {loss} vs PyTorch {expected_loss}"
    );
    let after = tempfile::tempdir().unwrap();
    model.save(after.path()).unwrap();
    let ours = Tensor::read_safetensors(after.path().join("forward_model.safetensors")).unwrap();
    for (name, tensor) in &ours {
        let (mine, theirs) = (
            floats(tensor),
            floats(get(&data, &format!("expected.{name}"))),
        );
        let before = floats(get(&data, name));
        for i in 0..mine.len() {
            assert!(
                (mine[i] - theirs[i]).abs() <= 1e-6,
                "{name}[{i}]: {} vs PyTorch {}",
                mine[i],
                theirs[i]
            );
        }
        assert!(
            mine.iter().zip(&before).any(|(a, b)| a != b),
            "{name} moved"
        );
    }
}
