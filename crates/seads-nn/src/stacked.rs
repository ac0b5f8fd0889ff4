//! The same network for K members at once: each member's parameters are a row of one
//! `[K, P]` buffer, each layer one batched product over the members (`baddbmm` on
//! `[K, batch, in]` inputs), and one optimiser step updates every member, each with its own
//! learning rate and step count. Members are stacked from, and unstacked back into, networks
//! built one by one ([`Adam`], [`flatten_parameters`]), so a member's state round-trips
//! exactly. The batched products round differently from a member's own `linear` (on the CPU
//! the weight gradients of some shapes differ in the last bits), so a stacked member follows
//! its solo run closely, not bit for bit.

use tch::{Device, Kind, Tensor};

use crate::Adam;

/// The parameters of K members, stacked: a `[K, P]` buffer whose rows are the members' flat
/// buffers ([`flatten_parameters`](crate::flatten_parameters)), and a `[K, shape…]` view of it
/// per variable.
#[derive(Debug)]
pub struct StackedParameters {
    flat: Tensor,
    named: Vec<(String, Tensor)>,
}

impl StackedParameters {
    /// Stacks the members' flat buffers `flats` (each laid out as `layout`, from
    /// [`parameter_layout`](crate::parameter_layout)) onto `device`. With `trainable`, the views
    /// are leaves that gradients can be taken with respect to.
    ///
    /// # Panics
    /// If a buffer's length is not the layout's.
    pub fn stack(
        flats: &[&Tensor],
        layout: &[(String, Vec<i64>)],
        device: Device,
        trainable: bool,
    ) -> Self {
        tch::no_grad(|| {
            let rows: Vec<Tensor> = flats.iter().map(|f| f.to_device(device)).collect();
            let flat = Tensor::stack(&rows, 0);
            let k = flat.size()[0];
            let mut offset = 0;
            let named = layout
                .iter()
                .map(|(name, shape)| {
                    let n: i64 = shape.iter().product();
                    let stacked: Vec<i64> =
                        std::iter::once(k).chain(shape.iter().copied()).collect();
                    let view = flat.narrow(1, offset, n).view(stacked.as_slice());
                    offset += n;
                    // A detached view shares the buffer's storage: updates of the buffer are
                    // the variables' updates.
                    let view = if trainable {
                        view.detach().set_requires_grad(true)
                    } else {
                        view
                    };
                    (name.clone(), view)
                })
                .collect();
            Self { flat, named }
        })
    }

    /// The `[K, P]` buffer.
    pub fn flat(&self) -> &Tensor {
        &self.flat
    }

    /// The number of members K.
    pub fn members(&self) -> usize {
        self.flat.size()[0] as usize
    }

    /// The stacked variable `name` (`[K, shape…]`).
    pub fn get(&self, name: &str) -> Option<&Tensor> {
        self.named.iter().find(|(n, _)| n == name).map(|(_, t)| t)
    }

    /// The stacked variables, in the order of the buffer.
    pub fn variables(&self) -> impl Iterator<Item = &Tensor> {
        self.named.iter().map(|(_, t)| t)
    }

    /// Copies member k's row into `targets[k]` (flat tensors of the row's length, on any
    /// device), with one transfer off the device for all members.
    pub fn unstack_into(&self, targets: &[&Tensor]) {
        tch::no_grad(|| {
            let device = targets.first().map_or(Device::Cpu, |t| t.device());
            let rows = self.flat.to_device(device);
            for (k, target) in targets.iter().enumerate() {
                target.shallow_clone().copy_(&rows.get(k as i64));
            }
        });
    }
}

/// A stacked linear layer: weights `[K, out, in]`, biases `[K, out]`.
#[derive(Debug)]
pub struct StackedLinear {
    ws: Tensor,
    bs: Tensor,
}

impl StackedLinear {
    /// The layer whose variables are `{prefix}.weight` and `{prefix}.bias` in `params`.
    pub fn new(params: &StackedParameters, prefix: &str) -> Option<Self> {
        Some(Self {
            ws: params.get(&format!("{prefix}.weight"))?.shallow_clone(),
            bs: params.get(&format!("{prefix}.bias"))?.shallow_clone(),
        })
    }

    /// `[K, batch, in]` → `[K, batch, out]`: each member's rows through its own weights.
    pub fn forward(&self, x: &Tensor) -> Tensor {
        self.bs
            .unsqueeze(1)
            .baddbmm(x, &self.ws.transpose(1, 2), 1, 1)
    }
}

/// A stacked [`Mlp`](crate::Mlp): Linear → ReLU → … → Linear per member.
#[derive(Debug)]
pub struct StackedMlp {
    layers: Vec<StackedLinear>,
}

impl StackedMlp {
    /// The MLP built by [`Mlp::new`](crate::Mlp::new) under the path `prefix`
    /// (`{prefix}.layer0`, `{prefix}.layer1`, …), stacked in `params`; `None` if it has no layer.
    pub fn new(params: &StackedParameters, prefix: &str) -> Option<Self> {
        let layers: Vec<StackedLinear> = (0..)
            .map_while(|i| StackedLinear::new(params, &format!("{prefix}.layer{i}")))
            .collect();
        (!layers.is_empty()).then_some(Self { layers })
    }

    /// The last hidden activation (after its ReLU).
    pub fn features(&self, x: &Tensor) -> Tensor {
        let (hidden, _) = self.layers.split_at(self.layers.len() - 1);
        hidden
            .iter()
            .fold(x.shallow_clone(), |h, l| l.forward(&h).relu())
    }

    /// The output layer.
    pub fn head(&self) -> &StackedLinear {
        self.layers.last().expect("a stacked MLP has a layer")
    }

    /// `[K, batch, in]` → `[K, batch, out]`.
    pub fn forward(&self, x: &Tensor) -> Tensor {
        self.head().forward(&self.features(x))
    }
}

/// [`Adam`] over stacked parameters: the same formula per member, with the member's learning
/// rate and step count. The step counts live on the device, so a step never waits for it.
#[derive(Debug)]
pub struct StackedAdam {
    params: StackedParameters,
    /// Per member, `[K, 1]` in double precision, as [`Adam`] computes its bias corrections.
    lr: Tensor,
    steps: Tensor,
    m: Tensor,
    v: Tensor,
}

impl StackedAdam {
    /// Stacks the members' optimisers (parameters, moments, step counts) onto `device`; their
    /// parameters are laid out as `layout` ([`parameter_layout`](crate::parameter_layout) of
    /// the var store each optimises).
    pub fn stack(members: &[&Adam], layout: &[(String, Vec<i64>)], device: Device) -> Self {
        let flats: Vec<&Tensor> = members.iter().map(|a| a.parameters()).collect();
        let params = StackedParameters::stack(&flats, layout, device, true);
        let moments = |pick: fn(&Adam) -> &Tensor| {
            tch::no_grad(|| {
                let rows: Vec<Tensor> = members.iter().map(|a| pick(a).to_device(device)).collect();
                Tensor::stack(&rows, 0)
            })
        };
        let column = |values: Vec<f64>| {
            Tensor::from_slice(&values)
                .view([members.len() as i64, 1])
                .to_device(device)
        };
        Self {
            m: moments(|a| a.moments().0),
            v: moments(|a| a.moments().1),
            lr: column(members.iter().map(|a| a.lr()).collect()),
            steps: column(members.iter().map(|a| a.steps_taken()).collect()),
            params,
        }
    }

    /// The optimised parameters.
    pub fn parameters(&self) -> &StackedParameters {
        &self.params
    }

    /// Back-propagates `loss` (the sum of the members' losses) to the stacked parameters only
    /// and updates each member by Adam.
    pub fn backward_step(&mut self, loss: &Tensor) {
        let variables: Vec<Tensor> = self.params.variables().map(Tensor::shallow_clone).collect();
        let grads = Tensor::run_backward(&[loss], &variables, false, false);
        let k = self.params.members() as i64;
        tch::no_grad(|| {
            let rows: Vec<Tensor> = grads
                .iter()
                .zip(&variables)
                .map(|(g, p)| {
                    if g.defined() {
                        g.reshape([k, -1])
                    } else {
                        p.zeros_like().reshape([k, -1])
                    }
                })
                .collect();
            let mut g = Tensor::cat(&rows, 1);
            let _ = self.steps.g_add_scalar_(1.0);
            // The bias corrections 1 − βᵗ per member, in double precision like Adam's.
            let correction = |beta: f64| -> Tensor { 1.0 - Tensor::pow_scalar(beta, &self.steps) };
            let sqrt_c2 = correction(Adam::BETA2).sqrt().to_kind(Kind::Float);
            // −1 / step size, the step size being lr / (1 − β₁ᵗ).
            let neg_inv_step = (-correction(Adam::BETA1) / &self.lr).to_kind(Kind::Float);
            let _ = self.m.lerp_(&g, 1.0 - Adam::BETA1);
            let _ = self.v.lerp_(&g.square_(), 1.0 - Adam::BETA2);
            let mut denom = crate::numerics::sqrt(&self.v);
            let _ = denom
                .g_div_(&sqrt_c2)
                .g_add_scalar_(Adam::EPS)
                .g_mul_(&neg_inv_step);
            let _ = self.params.flat.addcdiv_(&self.m, &denom);
        });
    }

    /// Writes member k's parameters, moments and step count into `members[k]`.
    pub fn unstack_into(&self, members: &mut [&mut Adam]) {
        let rows = |t: &Tensor| tch::no_grad(|| t.to_device(Device::Cpu));
        let (flat, m, v) = (rows(&self.params.flat), rows(&self.m), rows(&self.v));
        let steps = Vec::<f64>::try_from(rows(&self.steps).view([-1])).expect("double step counts");
        for ((k, member), t) in members.iter_mut().enumerate().zip(steps) {
            let k64 = k as i64;
            member.restore(&flat.get(k64), &m.get(k64), &v.get(k64), t);
        }
    }
}

/// `values` as a float tensor of `shape` on `device`.
pub fn upload(values: &[f32], shape: &[i64], device: Device) -> Tensor {
    Tensor::from_slice(values).view(shape).to_device(device)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Init, Mlp, parameter_layout};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use tch::Kind;
    use tch::nn::{self, Module};

    /// Three members of different initialisations and learning rates: stacked steps follow the
    /// members' own steps (to rounding), and unstacking writes back what they would hold.
    #[test]
    fn stacked_adam_follows_each_member_and_unstacks_into_it() {
        let lrs = [1e-2, 3e-3, 5e-2];
        let build = |k: usize| {
            let vs = nn::VarStore::new(Device::Cpu);
            let net = Mlp::new(
                &(vs.root() / "net"),
                3,
                &[8, 8],
                2,
                Init::TorchDefault,
                &mut ChaCha8Rng::seed_from_u64(k as u64),
            );
            let adam = Adam::new(&vs, lrs[k]);
            (vs, net, adam)
        };
        let data = |k: usize, cols: i64, salt: usize| {
            let v: Vec<f32> = (0..16 * cols as usize)
                .map(|i| (((i + 3 * k + salt) * 7 % 13) as f32 - 6.0) / 4.0)
                .collect();
            Tensor::from_slice(&v).view([16, cols])
        };
        let mut solo: Vec<_> = (0..3).map(build).collect();
        let mut copies: Vec<_> = (0..3).map(build).collect();
        let layout = parameter_layout(&solo[0].0);
        let adams: Vec<&Adam> = copies.iter().map(|(_, _, a)| a).collect();
        let mut stacked = StackedAdam::stack(&adams, &layout, Device::Cpu);
        let net = StackedMlp::new(stacked.parameters(), "net").unwrap();
        let x = Tensor::stack(&(0..3).map(|k| data(k, 3, 0)).collect::<Vec<_>>(), 0);
        let y = Tensor::stack(&(0..3).map(|k| data(k, 2, 5)).collect::<Vec<_>>(), 0);
        for _ in 0..10 {
            for (k, (_, net, adam)) in solo.iter_mut().enumerate() {
                let loss = (net.forward(&data(k, 3, 0)) - data(k, 2, 5))
                    .square()
                    .mean(Kind::Float);
                adam.backward_step(&loss);
            }
            let loss = (net.forward(&x) - &y)
                .square()
                .mean_dim([1, 2].as_slice(), false, Kind::Float)
                .sum(Kind::Float);
            stacked.backward_step(&loss);
        }
        let mut targets: Vec<&mut Adam> = copies.iter_mut().map(|(_, _, a)| a).collect();
        stacked.unstack_into(&mut targets);
        for ((_, _, ours), (_, _, theirs)) in copies.iter().zip(&solo) {
            let diff =
                f64::try_from((ours.parameters() - theirs.parameters()).abs().max()).unwrap();
            assert!(diff < 1e-5, "{diff}");
            assert_eq!(ours.steps_taken(), 10.0);
            let (m, _) = ours.moments();
            assert!(f64::try_from((m - theirs.moments().0).abs().max()).unwrap() < 1e-5);
        }
        // Stacking and unstacking without a step changes no bit.
        let before: Vec<Tensor> = copies
            .iter()
            .map(|(_, _, a)| a.parameters().copy())
            .collect();
        let adams: Vec<&Adam> = copies.iter().map(|(_, _, a)| a).collect();
        let again = StackedAdam::stack(&adams, &layout, Device::Cpu);
        let mut targets: Vec<&mut Adam> = copies.iter_mut().map(|(_, _, a)| a).collect();
        again.unstack_into(&mut targets);
        for ((_, _, a), b) in copies.iter().zip(&before) {
            assert!(a.parameters().equal(b));
        }
    }
}
