//! The network blocks of SEADS's learners, on tch: MLPs with the reference's initialisations
//! ([`Init`]: Xavier for SAC, PyTorch's default for the skill models) drawn from a seeded stream, a flat view of a variable store's parameters, and an
//! Adam whose state can be checkpointed. The skill model (`seads-skillmodel`) and SAC (`seads-rl`)
//! are built from them.

mod device;
pub mod numerics;
pub mod process;
mod stacked;

pub use device::{ComputeDevice, DeviceError, Resolve};
pub use seads_weights::WeightsError;
pub use stacked::{StackedAdam, StackedLinear, StackedMlp, StackedParameters, upload};

use rand::{Rng, RngExt};
use tch::nn::{self, Module};
use tch::{Kind, Tensor};

/// How a linear layer's weights and biases start, as the reference starts its networks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Init {
    /// Xavier-uniform weights (gain 1), U(±√(6 / (fan_in + fan_out))), and zero biases: the
    /// reference's SAC networks (`weights_init_` in its `sac/model.py`).
    Xavier,
    /// PyTorch's own `nn.Linear` initialisation: weights and biases both U(±1/√fan_in) (Kaiming
    /// uniform with a = √5 for the weights). The reference's forward model and VIC discriminator
    /// are plain `nn.Sequential`s, so they start this way.
    TorchDefault,
}

/// A fully connected network: Linear → ReLU → … → Linear, every layer initialised by one
/// [`Init`]. The weights are drawn from the caller's seeded RNG, never from libtorch's global
/// generator, so that a seed fixes them whatever else runs in the process.
#[derive(Debug)]
pub struct Mlp {
    layers: Vec<nn::Linear>,
}

impl Mlp {
    /// An MLP `input → hidden[0] → … → output` with ReLU between layers, under `path`, each
    /// layer initialised by `init` from `rng` (layer by layer, weights before bias).
    pub fn new<R: Rng + ?Sized>(
        path: &nn::Path,
        input: i64,
        hidden: &[i64],
        output: i64,
        init: Init,
        rng: &mut R,
    ) -> Self {
        let sizes: Vec<i64> = std::iter::once(input)
            .chain(hidden.iter().copied())
            .chain([output])
            .collect();
        let layers = sizes
            .windows(2)
            .enumerate()
            .map(|(i, w)| linear(&(path / format!("layer{i}")), w[0], w[1], init, rng))
            .collect();
        Self { layers }
    }

    /// The last hidden activation (after its ReLU); `forward` applies the output layer to it.
    pub fn features(&self, x: &Tensor) -> Tensor {
        let (hidden, _) = self.layers.split_at(self.layers.len() - 1);
        hidden
            .iter()
            .fold(x.shallow_clone(), |h, l| l.forward(&h).relu())
    }

    /// The output layer.
    pub fn head(&self) -> &nn::Linear {
        self.layers.last().expect("an MLP has an output layer")
    }

    /// The layers, input first.
    pub fn layers(&self) -> &[nn::Linear] {
        &self.layers
    }
}

/// A linear layer `input → output` under `path`, initialised by `init` from `rng`.
pub fn linear<R: Rng + ?Sized>(
    path: &nn::Path,
    input: i64,
    output: i64,
    init: Init,
    rng: &mut R,
) -> nn::Linear {
    let config = nn::LinearConfig {
        ws_init: nn::Init::Const(0.0),
        bs_init: Some(nn::Init::Const(0.0)),
        bias: true,
    };
    let mut layer = nn::linear(path, input, output, config);
    let mut uniform = |bound: f32, n: i64| -> Vec<f32> {
        (0..n).map(|_| rng.random_range(-bound..bound)).collect()
    };
    let (weights, bias) = match init {
        Init::Xavier => {
            let bound = (6.0 / (input + output) as f64).sqrt() as f32;
            (uniform(bound, input * output), None)
        }
        Init::TorchDefault => {
            let bound = (1.0 / input as f64).sqrt() as f32;
            let weights = uniform(bound, input * output);
            (weights, Some(uniform(bound, output)))
        }
    };
    tch::no_grad(|| {
        let device = layer.ws.device();
        layer.ws.copy_(
            &Tensor::from_slice(&weights)
                .view([output, input])
                .to_device(device),
        );
        if let (Some(bias), Some(bs)) = (bias, layer.bs.as_mut()) {
            bs.copy_(&Tensor::from_slice(&bias).to_device(device));
        }
    });
    layer
}

/// A linear layer with Xavier-uniform weights (gain 1) drawn from `rng` and zero bias.
pub fn xavier_linear<R: Rng + ?Sized>(
    path: &nn::Path,
    input: i64,
    output: i64,
    rng: &mut R,
) -> nn::Linear {
    linear(path, input, output, Init::Xavier, rng)
}

impl Module for Mlp {
    fn forward(&self, x: &Tensor) -> Tensor {
        self.head().forward(&self.features(x))
    }
}

/// Loads the network weights of the safetensors file `path` (written by `VarStore::save`) into
/// `vs`, through [`seads_weights::Weights`], the one reader of checkpoints (the Python package's
/// agent reads them with it too): the file must hold exactly the variables of `vs`, each of
/// exactly its shape, float32 and finite; otherwise nothing is written and the error says why.
/// tch's own `VarStore::load` would take a `[1, 32]` weight for `[32, 32]` (the copy
/// broadcasts) or a float64 one (the variable changes its type, and the first product fails).
/// The values are copied into the variables in place, so views of them (the flat buffer of
/// [`flatten_parameters`]) see the loaded values.
pub fn load_var_store(
    vs: &mut nn::VarStore,
    path: &std::path::Path,
) -> Result<(), seads_weights::WeightsError> {
    let weights = seads_weights::Weights::read(path)?;
    let variables = vs.variables();
    weights.exactly(variables.keys().map(String::as_str))?;
    let mut checked = Vec::with_capacity(variables.len());
    for (name, variable) in variables {
        let size = variable.size();
        let shape: Vec<usize> = size.iter().map(|&d| d as usize).collect();
        let values = weights.tensor(&name, &shape)?;
        checked.push((variable, values, size));
    }
    // Every tensor is checked before any is written: a refused file leaves the network as it was.
    tch::no_grad(|| {
        for (mut variable, values, size) in checked {
            let source = Tensor::from_slice(&values)
                .reshape(size.as_slice())
                .to_device(variable.device());
            variable.copy_(&source);
        }
    });
    Ok(())
}

/// Moves every trainable variable of `vs` into one flat buffer, in name order, and returns it:
/// afterwards each variable is a view into the buffer, so whole-network updates (Adam, Polyak
/// averaging) are a few operations on the buffer instead of a few per variable.
pub fn flatten_parameters(vs: &nn::VarStore) -> Tensor {
    let mut named = trainable(vs);
    tch::no_grad(|| {
        let flat = Tensor::cat(
            &named.iter().map(|(_, p)| p.view([-1])).collect::<Vec<_>>(),
            0,
        );
        let mut offset = 0;
        for (_, p) in &mut named {
            let n = p.numel() as i64;
            p.set_data(&flat.narrow(0, offset, n).view(p.size().as_slice()));
            offset += n;
        }
        flat
    })
}

/// The names and shapes of the trainable variables of `vs` in the order of their flat buffer
/// ([`flatten_parameters`]).
pub fn parameter_layout(vs: &nn::VarStore) -> Vec<(String, Vec<i64>)> {
    trainable(vs)
        .into_iter()
        .map(|(name, t)| (name, t.size()))
        .collect()
}

/// The trainable variables of `vs`, sorted by name.
fn trainable(vs: &nn::VarStore) -> Vec<(String, Tensor)> {
    let mut named: Vec<(String, Tensor)> = vs
        .variables()
        .into_iter()
        .filter(|(_, t)| t.requires_grad())
        .collect();
    named.sort_by(|a, b| a.0.cmp(&b.0));
    named
}

/// Adam (PyTorch's defaults: β = (0.9, 0.999), ε = 1e-8, no weight decay) over the trainable
/// variables of a var store. Its moments live in a var store of their own, so a checkpoint of
/// that store restores the optimiser exactly (tch's own optimisers cannot be saved). The
/// parameters are flattened ([`flatten_parameters`]) so that a step is a few buffer operations.
#[derive(Debug)]
pub struct Adam {
    lr: f64,
    params: Vec<Tensor>,
    flat: Tensor,
    state: nn::VarStore,
    m: Tensor,
    v: Tensor,
    step: Tensor,
    /// `step`'s value on the host (read once after a restore), so that a step on a GPU does not
    /// wait for the device to read it.
    steps_taken: Option<f64>,
}

impl Adam {
    pub(crate) const BETA1: f64 = 0.9;
    pub(crate) const BETA2: f64 = 0.999;
    pub(crate) const EPS: f64 = 1e-8;

    /// Adam with learning rate `lr` over every trainable variable of `vs` (flattened, name order).
    pub fn new(vs: &nn::VarStore, lr: f64) -> Self {
        let flat = flatten_parameters(vs);
        let named = trainable(vs);
        let state = nn::VarStore::new(vs.device());
        let root = state.root();
        let m = root.zeros_no_train("m", &flat.size());
        let v = root.zeros_no_train("v", &flat.size());
        let step = root.zeros_no_train("step", &[1]);
        let params = named.into_iter().map(|(_, p)| p).collect();
        Self {
            lr,
            params,
            flat,
            state,
            m,
            v,
            step,
            steps_taken: Some(0.0),
        }
    }

    /// One update from the gradient `g` of the flat parameters, in place, by PyTorch's Adam
    /// formula (the rounding may differ in the last bits); `g` is used as scratch space.
    fn step(&mut self, mut g: Tensor) {
        tch::no_grad(|| {
            let t = 1.0 + self.steps_taken();
            self.steps_taken = Some(t);
            let _ = self.step.g_add_scalar_(1.0);
            let (c1, c2) = (1.0 - Self::BETA1.powf(t), 1.0 - Self::BETA2.powf(t));
            // m ← β₁·m + (1 − β₁)·g and v ← β₂·v + (1 − β₂)·g², as interpolations.
            let _ = self.m.lerp_(&g, 1.0 - Self::BETA1);
            let _ = self.v.lerp_(&g.square_(), 1.0 - Self::BETA2);
            // θ ← θ − (lr / c₁)·m / (√v / √c₂ + ε), with the step size folded into the divisor.
            let step_size = self.lr / c1;
            let mut denom = numerics::sqrt(&self.v);
            let _ = denom
                .g_div_scalar_(c2.sqrt())
                .g_add_scalar_(Self::EPS)
                .g_mul_scalar_(-1.0 / step_size);
            let _ = self.flat.addcdiv_(&self.m, &denom);
        });
    }

    /// The flat parameter buffer the optimised variables are views of.
    pub fn parameters(&self) -> &Tensor {
        &self.flat
    }

    /// Back-propagates `loss` to the optimised parameters only (other variables of the graph get
    /// no gradient) and updates them.
    pub fn backward_step(&mut self, loss: &Tensor) {
        let grads = Tensor::run_backward(&[loss], &self.params, false, false);
        let g = tch::no_grad(|| {
            let flat: Vec<Tensor> = grads
                .iter()
                .zip(&self.params)
                .map(|(g, p)| {
                    // Gradients straight from autograd may be strided differently from their
                    // parameters: reshape copies only where it must.
                    if g.defined() {
                        g.reshape([-1])
                    } else {
                        p.zeros_like().view([-1])
                    }
                })
                .collect();
            Tensor::cat(&flat, 0)
        });
        self.step(g);
    }

    /// The learning rate.
    pub fn lr(&self) -> f64 {
        self.lr
    }

    /// Steps taken so far.
    pub fn steps_taken(&self) -> f64 {
        // Read from the state once after a restore, so that a step on a GPU does not wait.
        self.steps_taken
            .unwrap_or_else(|| f64::try_from(&self.step).expect("scalar step count"))
    }

    /// The first and second moments, flat like [`Adam::parameters`].
    pub fn moments(&self) -> (&Tensor, &Tensor) {
        (&self.m, &self.v)
    }

    /// Overwrites the parameters, the moments and the step count (each flat tensor on any
    /// device, of the length of [`Adam::parameters`]): what another optimiser took over.
    pub fn restore(&mut self, parameters: &Tensor, m: &Tensor, v: &Tensor, steps: f64) {
        tch::no_grad(|| {
            let device = self.flat.device();
            self.flat.copy_(&parameters.to_device(device));
            self.m.copy_(&m.to_device(device));
            self.v.copy_(&v.to_device(device));
            let _ = self.step.fill_(steps);
        });
        self.steps_taken = Some(steps);
    }

    /// The optimiser state (moments and step count), for checkpoints.
    pub fn state(&self) -> &nn::VarStore {
        &self.state
    }

    /// The optimiser state, for restoring checkpoints.
    pub fn state_mut(&mut self) -> &mut nn::VarStore {
        self.steps_taken = None;
        &mut self.state
    }
}

/// Mean over every element of a float tensor, as `f32`.
pub fn mean_f32(t: &Tensor) -> f32 {
    f32::try_from(t.mean(Kind::Float)).expect("a scalar")
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use tch::Device;
    use tch::nn::OptimizerConfig;

    /// Our Adam follows the same trajectory as tch's (libtorch's) Adam. Inputs and initial weights
    /// are shared copies, so the test does not depend on libtorch's global RNG.
    /// Adam divides by the root of `numerics::sqrt` (the correctly rounded one, with the portable
    /// kernels the tests run with), not by libtorch's, whose last bit depends on the processor:
    /// its first step equals the formula with the one root and, for these gradients, not with
    /// the other.
    #[test]
    fn adam_divides_by_the_portable_root() {
        let n = 4096;
        let grads: Vec<f32> = (0..n).map(|i| 1e-3 * (1.0 + i as f32 / 7.0)).collect();
        let vs = nn::VarStore::new(Device::Cpu);
        let _ = vs.root().zeros("w", &[n as i64]);
        let mut adam = Adam::new(&vs, 1e-2);
        let g = Tensor::from_slice(&grads);
        adam.step(g.copy());
        let after = |root: &dyn Fn(&Tensor) -> Tensor| {
            // Adam's bias corrections and step size at step 1, as `Adam::step` computes them.
            let (c1, c2) = (1.0 - Adam::BETA1.powf(1.0), 1.0 - Adam::BETA2.powf(1.0));
            let step_size = 1e-2 / c1;
            let m =
                Tensor::zeros([n as i64], (Kind::Float, Device::Cpu)).lerp(&g, 1.0 - Adam::BETA1);
            let v = Tensor::zeros([n as i64], (Kind::Float, Device::Cpu))
                .lerp(&g.square(), 1.0 - Adam::BETA2);
            let denom = root(&v)
                .g_div_scalar(c2.sqrt())
                .g_add_scalar(Adam::EPS)
                .g_mul_scalar(-1.0 / step_size);
            Tensor::zeros([n as i64], (Kind::Float, Device::Cpu)).addcdiv(&m, &denom)
        };
        assert!(
            numerics::portable_kernels_active(),
            "the tests run with the portable kernels"
        );
        let portable = after(&|v: &Tensor| numerics::sqrt(v));
        let libtorch = after(&|v: &Tensor| v.sqrt());
        assert!(adam.parameters().equal(&portable));
        assert!(
            !portable.equal(&libtorch),
            "these gradients should tell the two roots apart"
        );
    }

    #[test]
    fn adam_matches_libtorch() {
        let init = nn::VarStore::new(Device::Cpu);
        let _ = Mlp::new(
            &init.root(),
            3,
            &[8],
            2,
            Init::Xavier,
            &mut ChaCha8Rng::seed_from_u64(1),
        );
        let x = Tensor::from_slice(
            &(0..48)
                .map(|i| ((i * 7 % 13) as f32 - 6.0) / 4.0)
                .collect::<Vec<_>>(),
        )
        .view([16, 3]);
        let y = Tensor::from_slice(
            &(0..32)
                .map(|i| ((i * 5 % 11) as f32 - 5.0) / 3.0)
                .collect::<Vec<_>>(),
        )
        .view([16, 2]);
        let run = |ours: bool| {
            let mut vs = nn::VarStore::new(Device::Cpu);
            let net = Mlp::new(
                &vs.root(),
                3,
                &[8],
                2,
                Init::Xavier,
                &mut ChaCha8Rng::seed_from_u64(2),
            );
            vs.copy(&init).unwrap();
            let mut mine = Adam::new(&vs, 1e-2);
            let mut theirs = nn::Adam::default().build(&vs, 1e-2).unwrap();
            for _ in 0..20 {
                let loss = (net.forward(&x) - &y).square().mean(Kind::Float);
                if ours {
                    mine.backward_step(&loss);
                } else {
                    theirs.backward_step(&loss);
                }
            }
            net.forward(&x)
        };
        let diff = f64::try_from((run(true) - run(false)).abs().max()).unwrap();
        assert!(diff < 1e-5, "{diff}");
    }

    #[test]
    fn xavier_bounds_and_zero_bias() {
        let vs = nn::VarStore::new(Device::Cpu);
        let net = Mlp::new(
            &vs.root(),
            53,
            &[256, 256],
            3,
            Init::Xavier,
            &mut ChaCha8Rng::seed_from_u64(0),
        );
        let bound = (6.0f64 / (53.0 + 256.0)).sqrt();
        let w = &net.layers()[0].ws;
        assert!(f64::try_from(w.abs().max()).unwrap() <= bound);
        assert!(f64::try_from(w.abs().max()).unwrap() > 0.9 * bound);
        assert_eq!(
            f64::try_from(net.layers()[1].bs.as_ref().unwrap().abs().sum(Kind::Float)).unwrap(),
            0.0
        );
        assert_eq!(
            net.forward(&Tensor::zeros([4, 53], (Kind::Float, Device::Cpu)))
                .size(),
            [4, 3]
        );
        let again = Mlp::new(
            &nn::VarStore::new(Device::Cpu).root(),
            53,
            &[256, 256],
            3,
            Init::Xavier,
            &mut ChaCha8Rng::seed_from_u64(0),
        );
        assert!(
            again.layers()[2].ws.equal(&net.layers()[2].ws),
            "the seed fixes the weights"
        );
    }
}
