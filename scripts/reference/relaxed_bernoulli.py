"""Reference values for the RelaxedBernoulli (Concrete) distribution of the HAC high level
(SPEC §5.2): torch.distributions.RelaxedBernoulli's reparameterised samples, their gradient
with respect to the logits, and log-densities.

Samples: torch's `rsample` draws its uniforms with `torch.rand`; re-seeding and calling
`torch.rand` with the same shape recovers them, so the file holds the uniforms as well as the
samples torch made from them. Log-densities are taken at torch's samples and at fixed values in
(0, 1). Two temperatures (0.1 and 0.5, values of the seed's grid), logits in [-5, 5] (the
policy's clamp).

Writes data/reference/relaxed_bernoulli.safetensors, checked by
crates/seads-rl/tests/reference.rs. Run with the PyTorch that scripts/setup.sh installs
(torch 2.13.0):
    python3 scripts/reference/relaxed_bernoulli.py
"""

import pathlib

import torch
from safetensors_writer import write
from torch.distributions import RelaxedBernoulli

torch.set_default_dtype(torch.float32)
out = {}
logits = torch.tensor([[-5.0, -1.5, 0.0, 0.3, 2.0, 5.0], [1.0, -0.2, 4.0, -3.0, 0.7, -0.7]])
values = torch.tensor([[0.01, 0.2, 0.5, 0.7, 0.95, 0.999], [0.3, 0.45, 0.99, 0.05, 0.6, 0.4]])
for name, temperature in [("t01", 0.1), ("t05", 0.5)]:
    l = logits.clone().requires_grad_(True)
    dist = RelaxedBernoulli(torch.tensor(temperature), logits=l)
    torch.manual_seed(20261124)
    sample = dist.rsample()
    torch.manual_seed(20261124)
    uniforms = torch.rand(logits.shape)
    sample.sum().backward()
    out[f"{name}.uniforms"] = uniforms
    out[f"{name}.sample"] = sample.detach()
    out[f"{name}.sample_grad"] = l.grad.detach()
    out[f"{name}.log_prob_sample"] = dist.log_prob(sample.detach()).detach()
    out[f"{name}.log_prob_values"] = dist.log_prob(values).detach()
out["logits"] = logits
out["values"] = values
path = pathlib.Path(__file__).resolve().parents[2] / "data/reference/relaxed_bernoulli.safetensors"
write(path, out)
print(f"wrote {path}")
