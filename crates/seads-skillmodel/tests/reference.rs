//! The forward model against PyTorch: log q(z_T | z_0, k) of a batch for every skill, the loss
//! of a labelled batch and the weights after one Adam step equal PyTorch's at the same weights and
//! inputs (data/reference/forward_model.safetensors, written by
//! scripts/reference/forward_model.py with torch.nn, torch.distributions.Bernoulli and
//! torch.optim.Adam); and both skill models start with the distribution of PyTorch's default
//! `nn.Linear` initialisation (data/reference/torch_linear_init.json, written by
//! scripts/reference/torch_linear_init.py). The mixture model (issue 80) against NumPy: its
//! log-likelihoods for every skill, its successors and its loss at the same weights and inputs
//! (data/reference/mixture_model.safetensors, written by scripts/reference/mixture_model.py).

use std::path::Path;

use seads_games::Successor as _;
use seads_games::SymbolicState;
use seads_skillmodel::{
    ForwardModel, MixtureModel, SkillDiscriminator, SkillModel, SkillModelConfig, SkillModelKind,
    SkillTransition,
};
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

/// Gives `model` the reference's weights of its network `name` (three layers): saved, its
/// weights file replaced by the reference's tensors, loaded back (with the optimiser's state).
fn load_reference_weights(model: &mut dyn SkillModel, data: &[(String, Tensor)], name: &str) {
    let dir = tempfile::tempdir().unwrap();
    model.save(dir.path()).unwrap();
    let weights: Vec<(String, Tensor)> = data
        .iter()
        .filter(|(n, _)| n.starts_with(&format!("{name}.")))
        .map(|(n, t)| (n.clone(), t.shallow_clone()))
        .collect();
    assert_eq!(weights.len(), 6);
    Tensor::write_safetensors(&weights, dir.path().join(format!("{name}.safetensors"))).unwrap();
    model.load(dir.path(), true).unwrap();
}

/// The reference's states (`input.z0`, `input.zt`) and the model's scores of their pairs, checked
/// against `expected.scores` within `tolerance` (relative, beyond 1).
#[allow(clippy::type_complexity)]
fn scores_match(
    model: &dyn SkillModel,
    data: &[(String, Tensor)],
    d: usize,
    tolerance: f32,
) -> (
    Vec<SymbolicState>,
    Vec<SymbolicState>,
    Vec<(SymbolicState, SymbolicState)>,
    Vec<f32>,
) {
    let z0 = states(get(data, "input.z0"), d);
    let zt = states(get(data, "input.zt"), d);
    let pairs: Vec<_> = z0.iter().copied().zip(zt.iter().copied()).collect();
    let scores = model.scores(&pairs);
    let expected = floats(get(data, "expected.scores"));
    assert_eq!(scores.len(), expected.len());
    for (i, (a, b)) in scores.iter().zip(&expected).enumerate() {
        assert!(
            (a - b).abs() <= tolerance * (1.0 + b.abs()),
            "score {i}: {a} vs the reference's {b}"
        );
    }
    (z0, zt, pairs, scores)
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
    load_reference_weights(&mut model, &data, "forward_model");

    let (z0, zt, _, _) = scores_match(&model, &data, d, 1e-5);

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

/// The pooled statistics of one parameter (a layer's weights or biases) over several seeds.
struct Pooled {
    n: f64,
    max_abs: f64,
    mean: f64,
    std: f64,
    quantiles: Vec<f64>,
}

impl Pooled {
    fn of(mut values: Vec<f64>, levels: &[f64]) -> Self {
        values.sort_by(f64::total_cmp);
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let std = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
        // torch.quantile's default: linear interpolation between the closest ranks.
        let quantiles = levels
            .iter()
            .map(|p| {
                let pos = p * (n - 1.0);
                let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
                values[lo] + (values[hi] - values[lo]) * (pos - pos.floor())
            })
            .collect();
        let max_abs = values[0].abs().max(values[values.len() - 1].abs());
        Self {
            n,
            max_abs,
            mean,
            std,
            quantiles,
        }
    }

    fn from_json(v: &serde_json::Value) -> Self {
        let f = |k: &str| v[k].as_f64().unwrap();
        Self {
            n: f("n"),
            max_abs: f("min").abs().max(f("max").abs()),
            mean: f("mean"),
            std: f("std"),
            quantiles: v["quantiles"]
                .as_array()
                .unwrap()
                .iter()
                .map(|q| q.as_f64().unwrap())
                .collect(),
        }
    }

    /// Whether `self` (ours) and `torch` are two samples of one distribution on [-b, b], b
    /// estimated from torch's sample: each statistic within six standard errors of the difference
    /// of two independent samples (a uniform's: mean b/√(3n), standard deviation 0.26·b/√n,
    /// p-quantile 2b·√(p(1-p)/n)), and no value beyond torch's extremes by more than a few gaps.
    fn differs_from(&self, torch: &Self, levels: &[f64]) -> Option<String> {
        let b = torch.max_abs;
        let both = |se_ours: f64, se_torch: f64| 6.0 * (se_ours.powi(2) + se_torch.powi(2)).sqrt();
        let se_mean = |n: f64| b / (3.0 * n).sqrt();
        let se_std = |n: f64| 0.26 * b / n.sqrt();
        if self.max_abs > b * (1.0 + 10.0 / torch.n.min(self.n)) {
            return Some(format!("max |x| {} beyond torch's {b}", self.max_abs));
        }
        if (self.mean - torch.mean).abs() > both(se_mean(self.n), se_mean(torch.n)) {
            return Some(format!("mean {} against torch's {}", self.mean, torch.mean));
        }
        if (self.std - torch.std).abs() > both(se_std(self.n), se_std(torch.n)) {
            return Some(format!("std {} against torch's {}", self.std, torch.std));
        }
        for ((p, ours), theirs) in levels.iter().zip(&self.quantiles).zip(&torch.quantiles) {
            let se = |n: f64| 2.0 * b * (p * (1.0 - p) / n).sqrt();
            if (ours - theirs).abs() > both(se(self.n), se(torch.n)) {
                return Some(format!("{p}-quantile {ours} against torch's {theirs}"));
            }
        }
        None
    }
}

/// The forward model and the VIC discriminator start as the reference's plain `nn.Sequential`s
/// do: every layer's weights and biases distributed as PyTorch's default `nn.Linear`
/// initialisation draws them (compared with torch's own draws over as many seeds). The SAC
/// networks' Xavier initialisation with zero biases fails this comparison on every bias.
#[test]
fn initial_weights_follow_pytorchs_linear() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/reference/torch_linear_init.json");
    let reference: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let seeds = reference["seeds"].as_u64().unwrap();
    let levels: Vec<f64> = reference["quantiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|q| q.as_f64().unwrap())
        .collect();
    let config = SkillModelConfig {
        hidden: vec![256, 256],
        ..SkillModelConfig::default()
    };
    // (d, k) = (25, 25): LightsOutCursor's board and skills, the shapes the script draws.
    let (d, k) = (25, 25);
    let mut drawn: std::collections::BTreeMap<String, Vec<f64>> = Default::default();
    for seed in 0..seeds {
        let dir = tempfile::tempdir().unwrap();
        let models: [Box<dyn SkillModel>; 2] = [
            Box::new(ForwardModel::new(d, k, &config, Device::Cpu, seed)),
            Box::new(SkillDiscriminator::new(d, k, &config, Device::Cpu, seed)),
        ];
        for model in &models {
            model.save(dir.path()).unwrap();
        }
        for file in ["forward_model", "discriminator"] {
            let tensors =
                Tensor::read_safetensors(dir.path().join(format!("{file}.safetensors"))).unwrap();
            for (name, t) in tensors {
                let values = floats(&t).into_iter().map(f64::from);
                drawn.entry(name).or_default().extend(values);
            }
        }
    }
    let layers = reference["layers"].as_array().unwrap();
    assert_eq!(layers.len(), 6);
    for layer in layers {
        for param in ["weight", "bias"] {
            let name = format!(
                "{}.layer{}.{param}",
                layer["network"].as_str().unwrap(),
                layer["layer"]
            );
            let ours = Pooled::of(drawn.remove(&name).expect(&name), &levels);
            let torch = Pooled::from_json(&layer[param]);
            assert_eq!(ours.n, torch.n, "{name}: sample sizes");
            if let Some(why) = ours.differs_from(&torch, &levels) {
                panic!("{name}: {why}");
            }
        }
    }
    assert!(
        drawn.is_empty(),
        "parameters the reference lacks: {drawn:?}"
    );
}

/// The mixture model's likelihoods (the reward's and relabelling's scores, and the planner's step
/// log-probabilities), successors and loss equal NumPy's, computed from the formula in float64.
#[test]
fn the_mixture_models_likelihoods_successors_and_loss_match_numpy() {
    let (d, k, m) = (6, 3, 3);
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/reference/mixture_model.safetensors");
    let data = Tensor::read_safetensors(path).unwrap();
    let config = SkillModelConfig {
        kind: SkillModelKind::Mixture,
        components: Some(m),
        hidden: vec![8, 8],
        ..SkillModelConfig::default()
    };
    let mut model = MixtureModel::new(d, k, &config, Device::Cpu, 0);
    load_reference_weights(&mut model, &data, "mixture_model");

    let (z0, zt, pairs, scores) = scores_match(&model, &data, d, 1e-4);
    // The planner's step log-probabilities are the same numbers.
    let steps: Vec<_> = pairs
        .iter()
        .flat_map(|&(a, b)| (0..k).map(move |s| (a, s, b)))
        .collect();
    let by_step = model.log_likelihoods(&steps).unwrap();
    assert_eq!(by_step, scores);

    let mut next = Vec::new();
    model.successors(&z0, &mut next);
    assert_eq!(next, states(get(&data, "expected.successors"), d));

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
        (loss - expected_loss).abs() <= 1e-5 * (1.0 + expected_loss.abs()),
        "loss {loss} vs NumPy {expected_loss}"
    );
}
