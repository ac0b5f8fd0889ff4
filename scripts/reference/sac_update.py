"""Reference values for one SAC update (SPEC §3.2), computed with PyTorch's own modules and
optimiser: torch.nn.Linear networks, torch.optim.Adam, the clipped double-Q target, the
reparameterised tanh-Gaussian policy and the Polyak update, written from the specification.

Writes data/reference/sac_update.safetensors: the initial weights under the names seads-rl's
checkpoints use (`sac_actor.*`, `sac_critic.*`, `sac_target.*`), the batch, the two noise draws,
and the results (`expected.*`: losses, mean min-Q, the updated actor, critics and targets).
Checked by crates/seads-rl/tests/reference.rs.

Run with the PyTorch that scripts/setup.sh installs (torch 2.13.0) and its Python dependencies:
    python3 scripts/reference/sac_update.py
"""

import math
import pathlib

import torch
from safetensors_writer import write

torch.manual_seed(20221114)
torch.set_num_threads(1)
DTYPE = torch.float32

INPUT, ACTION, HIDDEN, ROWS = 7, 2, [8, 8], 5
LOW, HIGH = torch.tensor([-1.0, -2.0]), torch.tensor([1.0, 3.0])
LR, GAMMA, TAU, ALPHA = 1e-2, 0.99, 0.005, 0.1


def mlp(sizes):
    layers = []
    for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:])):
        layers.append(torch.nn.Linear(a, b))
        if i < len(sizes) - 2:
            layers.append(torch.nn.ReLU())
    return torch.nn.Sequential(*layers)


actor_body = mlp([INPUT] + HIDDEN + [ACTION])  # the last layer is the mean head
actor_log_std = torch.nn.Linear(HIDDEN[-1], ACTION)
q1, q2 = mlp([INPUT + ACTION] + HIDDEN + [1]), mlp([INPUT + ACTION] + HIDDEN + [1])
q1_target, q2_target = mlp([INPUT + ACTION] + HIDDEN + [1]), mlp([INPUT + ACTION] + HIDDEN + [1])
# Targets start as other weights than the critics, so that the Polyak step is visible.

scale, bias = (HIGH - LOW) / 2, (HIGH + LOW) / 2


def named(prefix, seq):
    """seads' names: <prefix>.layer<i>.weight / .bias, counting linear layers only."""
    out, i = {}, 0
    for module in seq:
        if isinstance(module, torch.nn.Linear):
            out[f"{prefix}.layer{i}.weight"] = module.weight.detach().clone()
            out[f"{prefix}.layer{i}.bias"] = module.bias.detach().clone()
            i += 1
    return out


def actor_weights():
    w = named("actor", actor_body)
    w["actor_log_std.weight"] = actor_log_std.weight.detach().clone()
    w["actor_log_std.bias"] = actor_log_std.bias.detach().clone()
    return w


def distribution(x):
    h = actor_body[:-1](x)
    return actor_body[-1](h), actor_log_std(h).clamp(-20.0, 2.0)


def sample(x, noise):
    mean, log_std = distribution(x)
    u = mean + log_std.exp() * noise
    t = torch.tanh(u)
    action = t * scale + bias
    log_normal = -0.5 * noise**2 - log_std - 0.5 * math.log(2 * math.pi)
    log_prob = (log_normal - torch.log(scale * (1 - t**2) + 1e-6)).sum(1, keepdim=True)
    return action, log_prob


def min_q(nets, x, a):
    xa = torch.cat([x, a], 1)
    return torch.minimum(nets[0](xa), nets[1](xa))


inputs = {
    "obs": torch.randn(ROWS, INPUT),
    "actions": (torch.rand(ROWS, ACTION) * 2 - 1) * scale + bias,
    "rewards": torch.randn(ROWS, 1),
    "next_obs": torch.randn(ROWS, INPUT),
    "dones": torch.tensor([[0.0], [1.0], [0.0], [0.0], [1.0]]),
    "next_noise": torch.randn(ROWS, ACTION),
    "policy_noise": torch.randn(ROWS, ACTION),
}
initial = {}
initial.update({f"sac_actor.{k}": v for k, v in actor_weights().items()})
initial.update({f"sac_critic.{k}": v for k, v in {**named("q1", q1), **named("q2", q2)}.items()})
initial.update(
    {f"sac_target.{k}": v for k, v in {**named("q1", q1_target), **named("q2", q2_target)}.items()}
)

critic_opt = torch.optim.Adam(list(q1.parameters()) + list(q2.parameters()), lr=LR)
actor_opt = torch.optim.Adam(
    list(actor_body.parameters()) + list(actor_log_std.parameters()), lr=LR
)

obs, actions, rewards = inputs["obs"], inputs["actions"], inputs["rewards"]
next_obs, dones = inputs["next_obs"], inputs["dones"]
with torch.no_grad():
    next_action, next_log_prob = sample(next_obs, inputs["next_noise"])
    soft_q = min_q((q1_target, q2_target), next_obs, next_action) - ALPHA * next_log_prob
    y = rewards + (1 - dones) * GAMMA * soft_q
xa = torch.cat([obs, actions], 1)
critic_loss = ((q1(xa) - y) ** 2).mean() + ((q2(xa) - y) ** 2).mean()
critic_opt.zero_grad()
critic_loss.backward()
critic_opt.step()

new_action, log_prob = sample(obs, inputs["policy_noise"])
q = min_q((q1, q2), obs, new_action)
actor_loss = (ALPHA * log_prob - q).mean()
actor_opt.zero_grad()
actor_loss.backward()  # the critics get gradients too, but their optimiser does not step
actor_opt.step()

with torch.no_grad():
    for target, source in ((q1_target, q1), (q2_target, q2)):
        for t, s in zip(target.parameters(), source.parameters()):
            t.mul_(1 - TAU).add_(TAU * s)

expected = {
    "expected.losses": torch.tensor([critic_loss.item(), actor_loss.item(), q.mean().item()]),
}
expected.update({f"expected.sac_actor.{k}": v for k, v in actor_weights().items()})
expected.update(
    {f"expected.sac_critic.{k}": v for k, v in {**named("q1", q1), **named("q2", q2)}.items()}
)
expected.update(
    {
        f"expected.sac_target.{k}": v
        for k, v in {**named("q1", q1_target), **named("q2", q2_target)}.items()
    }
)
out = pathlib.Path(__file__).resolve().parents[2] / "data/reference/sac_update.safetensors"
write(out, {**{f"input.{k}": v for k, v in inputs.items()}, **initial, **expected})
print(f"wrote {out}: critic loss {critic_loss.item():.6f}, actor loss {actor_loss.item():.6f}")
