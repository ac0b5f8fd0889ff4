//! Reinforcement learning for SEADS (SPEC §3.2): soft actor-critic on tch (libtorch) for the
//! skill-conditioned policy π(a | s, k). Will own the actor, the twin critics and their updates.
//!
//! Architecture invariant: with `seads-skillmodel`, the only crate that links libtorch.

#[cfg(test)]
mod tests {
    use tch::nn::{self, Module, OptimizerConfig};
    use tch::{Device, Kind, Tensor};

    /// libtorch is installed and linked: one Adam step of a small MLP lowers its loss.
    #[test]
    fn tch_smoke_adam_step_lowers_loss() {
        tch::manual_seed(0);
        let vs = nn::VarStore::new(Device::Cpu);
        let net = nn::seq()
            .add(nn::linear(vs.root() / "l1", 4, 16, Default::default()))
            .add_fn(|x| x.relu())
            .add(nn::linear(vs.root() / "l2", 16, 1, Default::default()));
        let mut opt = nn::Adam::default().build(&vs, 1e-2).expect("optimizer");
        let x = Tensor::randn([64, 4], (Kind::Float, Device::Cpu));
        let y = x.sum_dim_intlist(1, true, Kind::Float);
        let loss = |net: &nn::Sequential| (net.forward(&x) - &y).square().mean(Kind::Float);
        let before = f64::try_from(loss(&net)).unwrap();
        opt.backward_step(&loss(&net));
        let after = f64::try_from(loss(&net)).unwrap();
        assert!(after < before, "loss {before} -> {after}");
    }
}
