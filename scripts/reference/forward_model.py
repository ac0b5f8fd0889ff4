"""Reference values for the symbolic forward model (SPEC §3.4), computed with PyTorch's own
modules: an MLP on [z_0, onehot(k)] giving flip probabilities, the per-bit probability
alpha = (1 - z_0) p + z_0 (1 - p), and torch.distributions.Bernoulli's log-probability of z_T
(which clamps alpha to [eps, 1 - eps] as the reference does); the loss of a labelled batch (the
mean over the batch and the bits) and one Adam step on it.

Writes data/reference/forward_model.safetensors: the weights under seads' names
(`forward_model.layer<i>.*`), the states as 0/1 rows, log q(z_T | z_0, k) for every k, the loss,
and the weights after the step. Checked by crates/seads-skillmodel/tests/reference.rs.

Run with the PyTorch that scripts/setup.sh installs (torch 2.13.0):
    python3 scripts/reference/forward_model.py
"""

import pathlib

import torch
from safetensors_writer import write

torch.manual_seed(3242)
torch.set_num_threads(1)

D, K, HIDDEN, N, LR = 6, 3, [8, 8], 10, 1e-3

layers = []
sizes = [D + K] + HIDDEN + [D]
for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:])):
    layers.append(torch.nn.Linear(a, b))
    if i < len(sizes) - 2:
        layers.append(torch.nn.ReLU())
net = torch.nn.Sequential(*layers)


def weights(prefix):
    out = {}
    linear = [m for m in net if isinstance(m, torch.nn.Linear)]
    for i, m in enumerate(linear):
        out[f"{prefix}forward_model.layer{i}.weight"] = m.weight.detach().clone()
        out[f"{prefix}forward_model.layer{i}.bias"] = m.bias.detach().clone()
    return out


def log_q(z0, zt, k):
    onehot = torch.nn.functional.one_hot(k, K).float()
    p_flip = torch.sigmoid(net(torch.cat([z0, onehot], 1)))
    alpha = (1 - z0) * p_flip + z0 * (1 - p_flip)
    return torch.distributions.Bernoulli(probs=alpha).log_prob(zt)  # per bit


z0 = torch.randint(0, 2, (N, D)).float()
zt = torch.randint(0, 2, (N, D)).float()
labels = torch.randint(0, K, (N,))
initial = weights("")
with torch.no_grad():
    scores = torch.stack(
        [log_q(z0, zt, torch.full((N,), k)).sum(1) for k in range(K)], 1
    )  # N x K
opt = torch.optim.Adam(net.parameters(), lr=LR)
loss = -log_q(z0, zt, labels).mean()
opt.zero_grad()
loss.backward()
opt.step()

out = pathlib.Path(__file__).resolve().parents[2] / "data/reference/forward_model.safetensors"
write(
    out,
    {
        **initial,
        "input.z0": z0,
        "input.zt": zt,
        "input.labels": labels.float(),
        "expected.scores": scores,
        "expected.loss": loss.detach().reshape(1),
        **weights("expected."),
    },
)
print(f"wrote {out}: loss {loss.item():.6f}")
