//! Skill models: the symbolic forward model q(z_T | z_0, k) of SEADS (SPEC §3.4) and the VIC
//! discriminator q(k | z_0, z_T) (SPEC §3.9), behind one trait.

use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use seads_games::SymbolicState;
use tch::nn::{self, Module};
use tch::{Device, Kind, Tensor};

use crate::SkillModelError;
use crate::screen::{Activations, Int8Screen, MAX_WIDTH, MIN_ROWS};
use seads_nn::{Adam, Init, Mlp, mean_f32};
pub use seads_run::{SkillModelConfig, SkillModelKind};

/// States per successor call on a GPU (25 skills: 8·10⁵ network rows, about 2 GiB of
/// activations for 256-unit layers): enough rows that a call's launches and copies are a small
/// part of it.
const DEVICE_BATCH: usize = 32_768;

/// float32 machine epsilon: α is clamped to [ε, 1 − ε] as PyTorch's Bernoulli does.
pub(crate) const EPS: f64 = 1.192_092_9e-7;

/// One (relabelled) skill execution as the skill model sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkillTransition {
    /// Symbolic state before the skill.
    pub z0: SymbolicState,
    /// The skill label.
    pub skill: usize,
    /// Symbolic state after the skill.
    pub zt: SymbolicState,
}

/// A learned model of what skills do to the symbolic state.
pub trait SkillModel: Send {
    /// Number of skills K.
    fn num_skills(&self) -> usize;
    /// For each `(z_0, z_T)`, K scores ℓ_k (row-major, `pairs.len() × K`) with
    /// log q(k | z_0, z_T) = ℓ_k − logsumexp ℓ. Forward model: ℓ_k = log q(z_T | z_0, k).
    fn scores(&self, pairs: &[(SymbolicState, SymbolicState)]) -> Vec<f32>;
    /// Whether the scores are likelihoods of z_T, so that the novelty bonus is defined.
    fn scores_are_likelihoods(&self) -> bool;
    /// One gradient step on `batch`; returns the loss.
    fn train_step(&mut self, batch: &[SkillTransition]) -> f32;
    /// Writes the parameters and the optimiser state.
    fn save(&self, dir: &Path) -> Result<(), SkillModelError>;
    /// Reads what [`SkillModel::save`] wrote. With `optimiser`, the optimiser state must be there
    /// too (resuming training: a fresh optimiser would change the run); without, it is not read
    /// (evaluation).
    fn load(&mut self, dir: &Path, optimiser: bool) -> Result<(), SkillModelError>;
}

/// Network input rows `[z_0, onehot(k)]` for `d`-bit states and `k` skills, on `device`.
pub(crate) fn skill_inputs(
    z0: &[SymbolicState],
    skills: &[usize],
    d: usize,
    k: usize,
    device: Device,
) -> Tensor {
    let width = d + k;
    let mut data = vec![0.0f32; z0.len() * width];
    write_bits(&mut data, width, 0, z0.iter().copied(), d);
    for (row, &skill) in data.chunks_mut(width).zip(skills) {
        row[d + skill] = 1.0;
    }
    Tensor::from_slice(&data)
        .view([z0.len() as i64, width as i64])
        .to_device(device)
}

/// Writes the first `d` bits of each state as 0/1 floats into consecutive rows of width `width`
/// starting at column `offset`.
fn write_bits(
    rows: &mut [f32],
    width: usize,
    offset: usize,
    states: impl Iterator<Item = SymbolicState>,
    d: usize,
) {
    for (row, z) in rows.chunks_mut(width).zip(states) {
        z.write_f32(&mut row[offset..offset + d]);
    }
}

pub(crate) fn states_tensor(
    states: impl Iterator<Item = SymbolicState>,
    d: usize,
    device: Device,
) -> Tensor {
    let states: Vec<SymbolicState> = states.collect();
    let n = states.len();
    let mut data = vec![0.0f32; n * d];
    write_bits(&mut data, d, 0, states.into_iter(), d);
    Tensor::from_slice(&data)
        .view([n as i64, d as i64])
        .to_device(device)
}

/// The symbolic forward model (SPEC §3.4): an MLP on `[z_0, onehot(k)]` predicts per-bit flip
/// probabilities; q(z_T | z_0, k) is the product of the resulting Bernoullis.
#[derive(Debug)]
pub struct ForwardModel {
    d: usize,
    k: usize,
    device: Device,
    network: Trainable,
    /// Whether the successor function screens with 8-bit arithmetic (same successors).
    int8_screen: bool,
    /// The screen for the current weights (dropped when they change).
    screen: Option<Int8Screen>,
    /// (State, skill) rows screened in 8 bits, and those of them computed in float32.
    screen_counts: (u64, u64),
}

impl ForwardModel {
    /// A fresh model for `d`-bit states and `k` skills, initialised from `seed`.
    pub fn new(d: usize, k: usize, config: &SkillModelConfig, device: Device, seed: u64) -> Self {
        Self {
            d,
            k,
            device,
            network: Trainable::new("forward_model", d + k, d, config, device, seed),
            int8_screen: fast_int8_products(),
            screen: None,
            screen_counts: (0, 0),
        }
    }

    /// Whether the planner's successor function may compute with 8-bit integers first (by
    /// default, where [`fast_int8_products`]). Either way the successors are those of float32
    /// inference (`screen.rs`); off, every logit is computed in float32, which the benches
    /// compare against.
    pub fn set_int8_screen(&mut self, on: bool) {
        self.int8_screen = on;
    }

    /// A copy of this model's weights on `device`, built with `config` (the one this model was
    /// built with; the optimiser state is not copied): to plan on a GPU with a model fitted on
    /// the CPU, or the other way round.
    pub fn on_device(
        &self,
        config: &SkillModelConfig,
        device: Device,
    ) -> Result<Self, SkillModelError> {
        let mut model = Self::new(self.d, self.k, config, device, 0);
        model
            .network
            .vs
            .copy(&self.network.vs)
            .map_err(|e| SkillModelError::Checkpoint {
                path: format!("(the model's weights, copied to {device:?})"),
                reason: e.to_string(),
            })?;
        model.int8_screen = self.int8_screen;
        Ok(model)
    }

    /// Length D of the symbolic state.
    pub fn symbolic_len(&self) -> usize {
        self.d
    }

    /// The network, for fast inference elsewhere (the planner's successor function).
    pub fn network(&self) -> &Mlp {
        &self.network.net
    }

    /// Network input rows `[z_0, onehot(k)]`.
    fn inputs(&self, z0: &[SymbolicState], skills: &[usize]) -> Tensor {
        skill_inputs(z0, skills, self.d, self.k, self.device)
    }

    /// Per-bit log-likelihood of the observed outcome, from flip logits and whether each bit
    /// flipped (`flipped` = z_0 XOR z_T as 0/1). With p = σ(logit) the flip probability,
    /// P(bit after = observed) is p for a flipped bit and 1 − p = σ(−logit) otherwise, so the
    /// reference's clamped Bernoulli log-likelihood log clamp(α, ε, 1 − ε) equals
    /// clamp(log σ(±logit), log ε, log(1 − ε)).
    fn bit_log_likelihood(logits: &Tensor, flipped: &Tensor) -> Tensor {
        let sign = flipped * 2.0 - 1.0;
        (logits * sign)
            .log_sigmoid()
            .clamp(EPS.ln(), (1.0 - EPS).ln())
    }

    /// The network's layers as handles for inference on one thread.
    fn inference(&self) -> Inference {
        Inference::of(&self.network.net, self.d, self.k)
    }

    /// Flip logits of every state under every skill (n × K × D), the first layer factorised
    /// (z₀'s part once per state, each skill's column added per skill).
    pub fn flip_logits_all_skills(&self, z0: &Tensor) -> Tensor {
        self.inference().flip_logits_all_skills(z0)
    }

    /// Flip logits for each `(z_0, k)` (n × D): bit d flips in the mode iff its logit > 0.
    pub fn flip_logits(&self, z0: &[SymbolicState], skills: &[usize]) -> Tensor {
        tch::no_grad(|| self.network.net.forward(&self.inputs(z0, skills)))
    }

    /// How many (state, skill) pairs the successor function has screened in 8-bit arithmetic,
    /// and how many of them it computed in float32 because a logit lay within the screen's bound.
    pub fn screen_counts(&self) -> (u64, u64) {
        self.screen_counts
    }

    /// The successors of every state under every skill (state-major), computed where the model
    /// is: the mode's next bits in float32, packed 32 to an integer, so that only the new states
    /// leave the device. The planner's path on a GPU; on the CPU it gives the same states as the
    /// other paths (tested), only with more copying.
    pub fn device_successors(&self, states: &[SymbolicState]) -> Vec<SymbolicState> {
        if states.is_empty() {
            return Vec::new();
        }
        let (d, k) = (self.d, self.k);
        let words = d.div_ceil(32);
        let packed = tch::no_grad(|| {
            let z0 = states_tensor(states.iter().copied(), d, self.device);
            let logits = self.flip_logits_all_skills(&z0); // n × K × D
            let ones = z0.unsqueeze(1).gt(0.5);
            let next = mode_flips(&logits, &z0)
                .logical_xor(&ones)
                .to_kind(Kind::Int64);
            let next = next.constant_pad_nd([0, (words * 32 - d) as i64]);
            let weights = Tensor::from_slice(&(0..32).map(|b| 1i64 << b).collect::<Vec<_>>())
                .to_device(self.device);
            let packed = (next.view([states.len() as i64, k as i64, words as i64, 32]) * weights)
                .sum_dim_intlist(3, false, Kind::Int64);
            Vec::<i64>::try_from(packed.view([-1]).to_device(Device::Cpu)).expect("packed states")
        });
        packed
            .chunks(words)
            .map(|chunk| {
                let mut state = [0u64; SymbolicState::WORDS];
                for (i, &half) in chunk.iter().enumerate() {
                    state[i / 2] |= (half as u64) << (32 * (i % 2));
                }
                SymbolicState::from_words(state)
            })
            .collect()
    }

    /// The 8-bit screen for the current weights (built on first use), or `None` where it does
    /// not apply: switched off, not on the CPU, not two hidden layers, or a layer wider than
    /// 1,024.
    fn screen(&mut self) -> Option<&Int8Screen> {
        let layers = self.network.net.layers();
        let narrow = layers.iter().all(|l| l.ws.size()[1] <= MAX_WIDTH);
        if !self.int8_screen || self.device != Device::Cpu || layers.len() != 3 || !narrow {
            return None;
        }
        let bias = |l: &nn::Linear| l.bs.as_ref().expect("layers have biases").shallow_clone();
        Some(self.screen.get_or_insert_with(|| {
            tch::no_grad(|| {
                Int8Screen::new(
                    &layers[1].ws,
                    &bias(&layers[1]),
                    &layers[2].ws,
                    &bias(&layers[2]),
                )
            })
        }))
    }
}

/// Which bits flip in the mode of q (SPEC §4.1), from flip logits (n × K × D) and the states
/// (n × D, 0/1): a 0 flips iff its logit is > 0, a 1 iff it is ≥ 0 (n × K × D, bool).
fn mode_flips(logits: &Tensor, z0: &Tensor) -> Tensor {
    let ones = z0.unsqueeze(1).gt(0.5);
    logits
        .gt(0.0)
        .logical_or(&ones.logical_and(&logits.eq(0.0)))
}

/// Whether this processor has 8-bit dot products (VNNI), where libtorch's integer product
/// (`_int_mm`) runs through oneDNN: the 8-bit screen then made breadth-first search 1.4–1.5×
/// faster than float32 on a Zen 4 EPYC (docs/results/log-2026-11.md). Without them, libtorch
/// multiplies in a plain loop: on a Zen 3 EPYC (AVX2 only) `_int_mm_out_cpu` took 97 % of a
/// search's time, far slower than float32, so the screen stays off. Only speed depends on it: the
/// screen's successors are float32's.
pub fn fast_int8_products() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512vnni")
            || std::arch::is_x86_feature_detected!("avxvnni")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// States per part of a CPU successor call: the parts are computed on the rayon pool's threads,
/// always cut the same way, so that the successors do not depend on the number of threads.
const CPU_PART: usize = 512;

/// The first layer's rectified activations, factorised: row s·K + k is
/// relu(z₀ part of state s + column of skill k), both H₁ wide (as `flip_logits_all_skills`
/// computes them), built per row when the screen reads it.
struct FirstLayer {
    per_state: Vec<f32>,
    skill_cols: Vec<f32>,
    k: usize,
}

impl Activations for FirstLayer {
    fn write_row(&self, r: usize, out: &mut [f32]) {
        let h1 = out.len();
        let (state, skill) = (r / self.k, r % self.k);
        let a = &self.per_state[state * h1..(state + 1) * h1];
        let b = &self.skill_cols[skill * h1..(skill + 1) * h1];
        for ((x, &a), &b) in out.iter_mut().zip(a).zip(b) {
            *x = (a + b).max(0.0);
        }
    }
}

/// A forward model's layers for inference on one thread: shallow handles on its weights (a
/// tensor may be used from one thread at a time; the handles share the storage).
struct Inference {
    layers: Vec<nn::Linear>,
    d: usize,
    k: usize,
}

impl Inference {
    fn of(net: &Mlp, d: usize, k: usize) -> Self {
        let layers = net
            .layers()
            .iter()
            .map(|l| nn::Linear {
                ws: l.ws.shallow_clone(),
                bs: l.bs.as_ref().map(Tensor::shallow_clone),
            })
            .collect();
        Self { layers, d, k }
    }

    /// The first layer's rectified activations of every state under every skill, factorised
    /// as the screen reads them, and their width H₁.
    fn first_layer(&self, z0: &Tensor) -> (FirstLayer, usize) {
        let (per_state, skill_cols) = self.first_layer_parts(z0);
        let h1 = per_state.size()[1] as usize;
        let floats = |t: Tensor| Vec::<f32>::try_from(t.contiguous().view([-1])).expect("floats");
        let layer = FirstLayer {
            per_state: floats(per_state),
            skill_cols: floats(skill_cols),
            k: self.k,
        };
        (layer, h1)
    }

    /// The first layer split into its z_0 part, computed once per state with the bias (n × H),
    /// and each skill's column (K × H), added per skill.
    fn first_layer_parts(&self, z0: &Tensor) -> (Tensor, Tensor) {
        let first = &self.layers[0];
        let (d, k) = (self.d as i64, self.k as i64);
        let w_state = first.ws.narrow(1, 0, d);
        let bias = first.bs.as_ref().expect("layers have biases");
        let per_state = z0.matmul(&w_state.transpose(0, 1)) + bias;
        (per_state, first.ws.narrow(1, d, k).transpose(0, 1))
    }

    /// The layers after the first, on rectified first-layer activations (rows × H → rows × D).
    fn after_first_layer(&self, hidden: Tensor) -> Tensor {
        let layers = &self.layers[1..];
        layers.iter().enumerate().fold(hidden, |h, (i, layer)| {
            let h = layer.forward(&h);
            if i + 1 < layers.len() { h.relu() } else { h }
        })
    }

    /// Flip logits of every state under every skill (n × K × D).
    fn flip_logits_all_skills(&self, z0: &Tensor) -> Tensor {
        let (per_state, w_skill) = self.first_layer_parts(z0);
        let hidden = (per_state.unsqueeze(1) + w_skill.unsqueeze(0)).relu(); // n × K × H
        let (n, k) = (z0.size()[0], self.k as i64);
        self.after_first_layer(hidden.reshape([n * k, -1]))
            .view([n, k, self.d as i64])
    }

    /// The mode's flips (n × K × D, 1: the bit flips) in float32.
    fn exact_flips(&self, z0: &Tensor) -> Vec<u8> {
        let flip = mode_flips(&self.flip_logits_all_skills(z0), z0);
        Vec::<u8>::try_from(flip.to_kind(Kind::Uint8).view([-1]).to_device(Device::Cpu))
            .expect("flip table")
    }

    /// The same flips through the 8-bit screen (`screen.rs`), and the number of (state, skill)
    /// rows it left to float32.
    fn screened_flips(&self, z0: &Tensor, screen: &Int8Screen) -> (Vec<u8>, usize) {
        // The first layer exactly as `flip_logits_all_skills` computes it, each row built when
        // the screen reads it.
        let (d, k) = (self.d, self.k);
        let (hidden, h1) = self.first_layer(z0);
        let n = hidden.per_state.len() / h1;
        let floats = |t: Tensor| Vec::<f32>::try_from(t.contiguous().view([-1])).expect("floats");
        let mut flips = vec![0u8; n * k * d];
        let redo = screen.decide(&hidden, n * k, &mut flips);
        if !redo.is_empty() {
            // Those rows in float32, through the same layers as `flip_logits_all_skills`.
            let mut rows = vec![0.0f32; redo.len() * h1];
            for (out, &row) in rows.chunks_mut(h1).zip(&redo) {
                hidden.write_row(row, out);
            }
            let h = Tensor::from_slice(&rows).view([redo.len() as i64, h1 as i64]);
            let logits = floats(self.after_first_layer(h));
            let bits = floats(z0.shallow_clone());
            for (j, &row) in redo.iter().enumerate() {
                let state = row / k;
                for bit in 0..d {
                    let logit = logits[j * d + bit];
                    let one = bits[state * d + bit] > 0.5;
                    flips[row * d + bit] = u8::from(logit > 0.0 || (one && logit == 0.0));
                }
            }
        }
        (flips, redo.len())
    }

    /// The successors of `states` (state-major), through the screen where there is one and the
    /// part is large enough to gain from it; and the rows screened and recomputed.
    fn successors(
        &self,
        states: &[SymbolicState],
        screen: Option<&Int8Screen>,
    ) -> (Vec<SymbolicState>, u64, u64) {
        let (d, k) = (self.d, self.k);
        let (flips, screened, redone) = tch::no_grad(|| {
            let z0 = states_tensor(states.iter().copied(), d, Device::Cpu);
            match screen {
                Some(screen) if states.len() * k >= MIN_ROWS => {
                    let (flips, redone) = self.screened_flips(&z0, screen);
                    (flips, states.len() * k, redone)
                }
                _ => (self.exact_flips(&z0), 0, 0),
            }
        });
        let mut out = Vec::with_capacity(states.len() * k);
        for (&z, row) in states.iter().zip(flips.chunks(k * d)) {
            for skill in row.chunks(d) {
                let mut next = z;
                for (bit, &f) in skill.iter().enumerate() {
                    if f != 0 {
                        next.flip(bit);
                    }
                }
                out.push(next);
            }
        }
        (out, screened as u64, redone as u64)
    }
}

impl SkillModel for ForwardModel {
    fn num_skills(&self) -> usize {
        self.k
    }

    fn scores(&self, pairs: &[(SymbolicState, SymbolicState)]) -> Vec<f32> {
        if pairs.is_empty() {
            return Vec::new();
        }
        tch::no_grad(|| {
            let z0 = states_tensor(pairs.iter().map(|&(z0, _)| z0), self.d, self.device);
            let flipped = states_tensor(pairs.iter().map(|&(z0, zt)| z0 ^ zt), self.d, self.device);
            let logits = self.flip_logits_all_skills(&z0); // n × K × D
            let ll = Self::bit_log_likelihood(&logits, &flipped.unsqueeze(1)).sum_dim_intlist(
                2,
                false,
                Kind::Float,
            );
            Vec::<f32>::try_from(ll.view([-1]).to_device(Device::Cpu)).expect("float scores")
        })
    }

    fn scores_are_likelihoods(&self) -> bool {
        true
    }

    fn train_step(&mut self, batch: &[SkillTransition]) -> f32 {
        let z0: Vec<SymbolicState> = batch.iter().map(|t| t.z0).collect();
        let skills: Vec<usize> = batch.iter().map(|t| t.skill).collect();
        let logits = self.network.net.forward(&self.inputs(&z0, &skills));
        let flipped = states_tensor(batch.iter().map(|t| t.z0 ^ t.zt), self.d, self.device);
        // The reference averages over the batch and the D bits.
        let loss = -Self::bit_log_likelihood(&logits, &flipped).mean(Kind::Float);
        self.network.opt.backward_step(&loss);
        self.screen = None;
        mean_f32(&loss)
    }

    fn save(&self, dir: &Path) -> Result<(), SkillModelError> {
        self.network.save(dir)
    }

    fn load(&mut self, dir: &Path, optimiser: bool) -> Result<(), SkillModelError> {
        self.screen = None;
        self.network.load(dir, optimiser)
    }
}

/// The VIC skill discriminator (SPEC §3.9): log q(k | z_0, z_T) from `[z_0, z_T, z_0 XOR z_T]`.
#[derive(Debug)]
pub struct SkillDiscriminator {
    d: usize,
    k: usize,
    device: Device,
    network: Trainable,
}

impl SkillDiscriminator {
    /// A fresh discriminator for `d`-bit states and `k` skills, initialised from `seed`.
    pub fn new(d: usize, k: usize, config: &SkillModelConfig, device: Device, seed: u64) -> Self {
        Self {
            d,
            k,
            device,
            network: Trainable::new("discriminator", 3 * d, k, config, device, seed),
        }
    }

    fn log_posterior(
        &self,
        pairs: impl ExactSizeIterator<Item = (SymbolicState, SymbolicState)>,
    ) -> Tensor {
        let n = pairs.len();
        let width = 3 * self.d;
        let mut data = vec![0.0f32; n * width];
        for (row, (z0, zt)) in data.chunks_mut(width).zip(pairs) {
            z0.write_f32(&mut row[..self.d]);
            zt.write_f32(&mut row[self.d..2 * self.d]);
            (z0 ^ zt).write_f32(&mut row[2 * self.d..]);
        }
        let x = Tensor::from_slice(&data)
            .view([n as i64, width as i64])
            .to_device(self.device);
        self.network.net.forward(&x).log_softmax(1, Kind::Float)
    }
}

impl SkillModel for SkillDiscriminator {
    fn num_skills(&self) -> usize {
        self.k
    }

    fn scores(&self, pairs: &[(SymbolicState, SymbolicState)]) -> Vec<f32> {
        if pairs.is_empty() {
            return Vec::new();
        }
        let scores = tch::no_grad(|| self.log_posterior(pairs.iter().copied()));
        Vec::<f32>::try_from(scores.view([-1]).to_device(Device::Cpu)).expect("float scores")
    }

    fn scores_are_likelihoods(&self) -> bool {
        false
    }

    fn train_step(&mut self, batch: &[SkillTransition]) -> f32 {
        let log_q = self.log_posterior(batch.iter().map(|t| (t.z0, t.zt)));
        let labels = Tensor::from_slice(&batch.iter().map(|t| t.skill as i64).collect::<Vec<_>>())
            .to_device(self.device);
        let loss = log_q.nll_loss(&labels);
        self.network.opt.backward_step(&loss);
        mean_f32(&loss)
    }

    fn save(&self, dir: &Path) -> Result<(), SkillModelError> {
        self.network.save(dir)
    }

    fn load(&mut self, dir: &Path, optimiser: bool) -> Result<(), SkillModelError> {
        self.network.load(dir, optimiser)
    }
}

/// The checkpoint files of the skill models' optimiser states (read only when resuming).
pub const OPTIMISER_FILES: [&str; 3] = [
    "forward_model_adam.safetensors",
    "discriminator_adam.safetensors",
    "mixture_model_adam.safetensors",
];

/// A named network with its own var store and optimiser, saved as `<name>.safetensors` and
/// `<name>_adam.safetensors` (one of [`OPTIMISER_FILES`]; read only when resuming training).
#[derive(Debug)]
pub(crate) struct Trainable {
    name: &'static str,
    vs: nn::VarStore,
    pub(crate) net: Mlp,
    pub(crate) opt: Adam,
}

impl Trainable {
    pub(crate) fn new(
        name: &'static str,
        input: usize,
        output: usize,
        config: &SkillModelConfig,
        device: Device,
        seed: u64,
    ) -> Self {
        let vs = nn::VarStore::new(device);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let net = Mlp::new(
            &(vs.root() / name),
            input as i64,
            &config.hidden,
            output as i64,
            Init::TorchDefault,
            &mut rng,
        );
        let opt = Adam::new(&vs, config.lr);
        Self { name, vs, net, opt }
    }

    pub(crate) fn save(&self, dir: &Path) -> Result<(), SkillModelError> {
        let io = |path: PathBuf| {
            move |source| SkillModelError::Io {
                path: path.display().to_string(),
                source,
            }
        };
        let path = dir.join(format!("{}.safetensors", self.name));
        self.vs.save(&path).map_err(io(path.clone()))?;
        let path = dir.join(format!("{}_adam.safetensors", self.name));
        self.opt.state().save(&path).map_err(io(path.clone()))
    }

    pub(crate) fn load(&mut self, dir: &Path, optimiser: bool) -> Result<(), SkillModelError> {
        let corrupt = |path: &Path, e: seads_nn::WeightsError| SkillModelError::Checkpoint {
            path: path.display().to_string(),
            reason: match e {
                seads_nn::WeightsError::Damaged { reason, .. } => reason,
                seads_nn::WeightsError::Io { source, .. } => source.to_string(),
            },
        };
        let path = dir.join(format!("{}.safetensors", self.name));
        seads_nn::load_var_store(&mut self.vs, &path).map_err(|e| corrupt(&path, e))?;
        if optimiser {
            let path = dir.join(format!("{}_adam.safetensors", self.name));
            seads_nn::load_var_store(self.opt.state_mut(), &path).map_err(|e| corrupt(&path, e))?;
        }
        Ok(())
    }
}

impl seads_games::Successor for ForwardModel {
    fn num_skills(&self) -> usize {
        self.k
    }

    fn symbolic_len(&self) -> usize {
        self.d
    }

    /// The mode of q(· | z, k) for every state and skill (SPEC §4.1): bit d is 1 afterwards iff
    /// α_d > 0.5, i.e. a 0 flips iff its flip logit is > 0 and a 1 flips iff it is ≥ 0.
    fn successors(&mut self, states: &[SymbolicState], out: &mut Vec<SymbolicState>) {
        if states.is_empty() {
            return;
        }
        if self.device != Device::Cpu {
            out.extend(self.device_successors(states));
            return;
        }
        // Parts of a fixed size on the pool's threads, each with its own handles on the weights.
        let screen = self.screen().map(Int8Screen::shallow_clone);
        let parts: Vec<(Inference, Option<Int8Screen>, &[SymbolicState])> = states
            .chunks(CPU_PART)
            .map(|part| {
                let screen = screen.as_ref().map(Int8Screen::shallow_clone);
                (self.inference(), screen, part)
            })
            .collect();
        let done: Vec<(Vec<SymbolicState>, u64, u64)> = parts
            .into_par_iter()
            .map(|(inference, screen, part)| inference.successors(part, screen.as_ref()))
            .collect();
        out.reserve(states.len() * self.k);
        for (next, screened, redone) in done {
            out.extend(next);
            self.screen_counts.0 += screened;
            self.screen_counts.1 += redone;
        }
    }

    /// log q(z_T | z_0, k) of each step, as the forward model trains on it (only the steps' own
    /// skills are computed); `None` for a skill the model does not have.
    fn log_likelihoods(
        &mut self,
        steps: &[(SymbolicState, usize, SymbolicState)],
    ) -> Option<Vec<f32>> {
        if steps.iter().any(|&(_, k, _)| k >= self.k) {
            return None;
        }
        if steps.is_empty() {
            return Some(Vec::new());
        }
        let z0: Vec<SymbolicState> = steps.iter().map(|&(z, _, _)| z).collect();
        let skills: Vec<usize> = steps.iter().map(|&(_, k, _)| k).collect();
        tch::no_grad(|| {
            let logits = self.flip_logits(&z0, &skills); // n × D
            let flipped =
                states_tensor(steps.iter().map(|&(z, _, zt)| z ^ zt), self.d, self.device);
            let ll =
                Self::bit_log_likelihood(&logits, &flipped).sum_dim_intlist(1, false, Kind::Float);
            Vec::<f32>::try_from(ll.to_device(Device::Cpu)).ok()
        })
    }

    fn preferred_batch(&self) -> usize {
        if self.device == Device::Cpu {
            // Four parts for each of the pool's threads, so that uneven parts even out.
            4 * CPU_PART * rayon::current_num_threads()
        } else {
            DEVICE_BATCH
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference's formula, written out: α = (1 − z_0)·p + z_0·(1 − p), clamped, Bernoulli
    /// log-likelihood of z_T summed over bits.
    fn reference_log_likelihood(logits: &[f32], z0: SymbolicState, zt: SymbolicState) -> f64 {
        logits
            .iter()
            .enumerate()
            .map(|(d, &x)| {
                let p = 1.0 / (1.0 + (-(x as f64)).exp());
                let z = z0.get(d) as u8 as f64;
                let alpha = ((1.0 - z) * p + z * (1.0 - p)).clamp(EPS, 1.0 - EPS);
                if zt.get(d) {
                    alpha.ln()
                } else {
                    (1.0 - alpha).ln()
                }
            })
            .sum()
    }

    /// A step's log-probability for the planner is the score of its skill for its pair.
    #[test]
    fn step_log_likelihoods_are_the_scores_of_their_skills() {
        use seads_games::Successor as _;
        let mut model = ForwardModel::new(25, 25, &SkillModelConfig::default(), Device::Cpu, 4);
        let (a, b) = (
            SymbolicState::from_u64(0b1011),
            SymbolicState::from_u64(1 << 24 | 7),
        );
        let pairs = [(a, b), (b, b), (b, a)];
        let scores = model.scores(&pairs);
        let steps: Vec<_> = pairs
            .iter()
            .enumerate()
            .flat_map(|(i, &(z0, zt))| [(i, 0), (i, 9), (i, 24)].map(|(i, k)| (i, (z0, k, zt))))
            .collect();
        let ll = model
            .log_likelihoods(&steps.iter().map(|&(_, s)| s).collect::<Vec<_>>())
            .unwrap();
        for (&(i, (_, k, _)), got) in steps.iter().zip(ll) {
            let want = scores[i * 25 + k];
            assert!(
                (got - want).abs() <= 1e-5 * want.abs().max(1.0),
                "{i}, {k}: {got} vs {want}"
            );
        }
        assert_eq!(model.log_likelihoods(&[(a, 25, b)]), None, "no skill 25");
    }

    #[test]
    fn batched_scores_match_the_reference_formula() {
        let model = ForwardModel::new(25, 25, &SkillModelConfig::default(), Device::Cpu, 9);
        let pairs = [
            (
                SymbolicState::from_u64(0b1011),
                SymbolicState::from_u64(0b0110_0011),
            ),
            (
                SymbolicState::from_u64(1 << 24),
                SymbolicState::from_u64(1 << 24),
            ),
        ];
        let scores = model.scores(&pairs);
        for (i, &(z0, zt)) in pairs.iter().enumerate() {
            for k in 0..25 {
                let logits =
                    Vec::<f32>::try_from(model.flip_logits(&[z0], &[k]).view([-1])).unwrap();
                let expected = reference_log_likelihood(&logits, z0, zt);
                let got = scores[i * 25 + k] as f64;
                assert!(
                    (got - expected).abs() < 1e-3 * expected.abs().max(1.0),
                    "k {k}: {got} vs {expected}"
                );
            }
        }
    }

    /// The screen's first-layer rows, built per row, are the float path's activations.
    #[test]
    fn first_layer_rows_are_the_float_paths_activations() {
        let model = ForwardModel::new(25, 7, &SkillModelConfig::default(), Device::Cpu, 5);
        let states: Vec<SymbolicState> = (0..40u64)
            .map(|i| SymbolicState::from_u64(i.wrapping_mul(0x9e37_79b9) & ((1 << 25) - 1)))
            .collect();
        let z0 = states_tensor(states.iter().copied(), 25, Device::Cpu);
        let inference = model.inference();
        let (per_state, skill_cols) = inference.first_layer_parts(&z0);
        let expected = (per_state.unsqueeze(1) + skill_cols.unsqueeze(0)).relu(); // n × K × H₁
        let expected = Vec::<f32>::try_from(expected.contiguous().view([-1])).unwrap();
        let (rows, h1) = inference.first_layer(&z0);
        let mut row = vec![0.0f32; h1];
        for r in 0..states.len() * 7 {
            rows.write_row(r, &mut row);
            assert_eq!(row[..], expected[r * h1..(r + 1) * h1], "row {r}");
        }
    }

    /// The GPU's path (run here on the CPU) packs the float32 mode's states into words: the
    /// same successors as the CPU's path, for states of one, two and three words.
    #[test]
    fn the_device_path_gives_the_float32_successors() {
        use rand::RngExt;
        use seads_games::Successor;
        for (d, k, seed) in [(25, 25, 3), (70, 6, 4), (150, 4, 5)] {
            let mut model =
                ForwardModel::new(d, k, &SkillModelConfig::default(), Device::Cpu, seed);
            model.set_int8_screen(false);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let states: Vec<SymbolicState> = (0..300)
                .map(|_| {
                    let mut z = SymbolicState::ZERO;
                    for bit in 0..d {
                        z.set(bit, rng.random::<bool>());
                    }
                    z
                })
                .collect();
            let mut expected = Vec::new();
            model.successors(&states, &mut expected);
            // Every bit follows the mode's rule, computed one (state, skill) row at a time.
            for (i, &z) in states.iter().enumerate().take(20) {
                for skill in 0..k {
                    let logits =
                        Vec::<f32>::try_from(model.flip_logits(&[z], &[skill]).view([-1])).unwrap();
                    let next = expected[i * k + skill];
                    for (bit, &logit) in logits.iter().enumerate() {
                        let flips = logit > 0.0 || (z.get(bit) && logit == 0.0);
                        if (next.get(bit) != z.get(bit)) != flips {
                            // The factorised first layer rounds differently from the plain
                            // forward pass only next to 0.
                            assert!(
                                logit.abs() < 1e-4,
                                "state {i} skill {skill} bit {bit}: {logit}"
                            );
                        }
                    }
                    for bit in d..SymbolicState::MAX_BITS {
                        assert!(!next.get(bit));
                    }
                }
            }
            assert_eq!(model.device_successors(&states), expected, "d = {d}");
        }
    }

    /// A copy to a device (here the CPU, the only one CI has) holds the same weights, so it
    /// scores and plans as the original; the original keeps training on its own.
    #[test]
    fn a_model_copied_to_a_device_keeps_its_weights() {
        use seads_games::Successor;
        let config = SkillModelConfig::default();
        let mut model = ForwardModel::new(25, 25, &config, Device::Cpu, 11);
        let batch: Vec<SkillTransition> = (0..32)
            .map(|i| SkillTransition {
                z0: SymbolicState::from_u64(i * 7919 % (1 << 25)),
                skill: (i % 25) as usize,
                zt: SymbolicState::from_u64(i * 104_729 % (1 << 25)),
            })
            .collect();
        model.train_step(&batch);
        let mut copy = model.on_device(&config, Device::Cpu).unwrap();
        let pairs: Vec<_> = batch.iter().map(|t| (t.z0, t.zt)).collect();
        assert_eq!(model.scores(&pairs), copy.scores(&pairs));
        let states: Vec<_> = batch.iter().map(|t| t.z0).collect();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        model.successors(&states, &mut a);
        copy.successors(&states, &mut b);
        assert_eq!(a, b);
        model.train_step(&batch);
        assert_ne!(
            model.scores(&pairs),
            copy.scores(&pairs),
            "the copy shares no storage"
        );
    }

    #[test]
    fn saturated_logits_are_clamped_like_the_reference() {
        let logits = Tensor::from_slice(&[60.0f32, -60.0, 0.0]).view([1, 3]);
        let flipped = Tensor::from_slice(&[0.0f32, 0.0, 1.0]).view([1, 3]);
        let ll =
            Vec::<f32>::try_from(ForwardModel::bit_log_likelihood(&logits, &flipped).view([-1]))
                .unwrap();
        assert!(
            (ll[0] - EPS.ln() as f32).abs() < 1e-3,
            "a confidently predicted flip that did not happen costs log ε"
        );
        assert!(ll[1].abs() < 1e-6);
        assert!((ll[2] - 0.5f32.ln()).abs() < 1e-6);
    }
}
