"""Reference values for the mixture skill model (issue 80; crates/seads-skillmodel/src/mixture.rs),
computed independently in NumPy (float64): an MLP on [z_0, onehot(k)] with ReLU hidden layers
whose output is M mixture logits, then M blocks of D flip logits; per component the Bernoulli
log-likelihood of z_T written out from alpha = (1 - z_0) p + z_0 (1 - p) with p = sigmoid(flip
logit), clamped to [eps, 1 - eps] as torch.distributions.Bernoulli does; log q(z_T | z_0, k) =
log sum_m softmax(w)_m exp(sum_d log P_md). The successor of (z_0, k): each component's mode
(z_T,d = 1 iff alpha_md > 0.5), the one with the largest log q, the first among equal ones. The
loss of a labelled batch: minus the mean log q, divided by D.

Writes data/reference/mixture_model.safetensors: the weights under seads' names
(`mixture_model.layer<i>.*`), the states as 0/1 rows, log q(z_T | z_0, k) for every k, the
successor of every (z_0, k), and the loss. Checked by crates/seads-skillmodel/tests/reference.rs.

    python3 scripts/reference/mixture_model.py      (NumPy only)
"""

import pathlib

import numpy as np
from safetensors_writer import write

rng = np.random.default_rng(8080)
D, K, M, HIDDEN, N = 6, 3, 3, [8, 8], 12
EPS = np.finfo(np.float32).eps

sizes = [D + K] + HIDDEN + [M * (D + 1)]
weights = {}
for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:])):
    # float32 values, so that both sides start from the same numbers
    weights[f"mixture_model.layer{i}.weight"] = rng.normal(0, 1.5, (b, a)).astype(np.float32)
    weights[f"mixture_model.layer{i}.bias"] = rng.normal(0, 0.5, (b,)).astype(np.float32)


def network(x):
    h = x
    n = len(sizes) - 1
    for i in range(n):
        w = weights[f"mixture_model.layer{i}.weight"].astype(np.float64)
        b = weights[f"mixture_model.layer{i}.bias"].astype(np.float64)
        h = h @ w.T + b
        if i < n - 1:
            h = np.maximum(h, 0.0)
    return h


def heads(z0, k):
    x = np.concatenate([z0, np.eye(K)[k]])
    out = network(x)
    w = out[:M]
    log_pi = w - np.log(np.sum(np.exp(w - w.max()))) - w.max()
    return log_pi, out[M:].reshape(M, D)


def log_q(z0, zt, k):
    log_pi, flips = heads(z0, k)
    total = []
    for m in range(M):
        p = 1.0 / (1.0 + np.exp(-flips[m]))
        alpha = np.clip((1 - z0) * p + z0 * (1 - p), EPS, 1 - EPS)
        total.append(log_pi[m] + np.sum(np.where(zt == 1, np.log(alpha), np.log(1 - alpha))))
    total = np.array(total)
    top = total.max()
    return top + np.log(np.sum(np.exp(total - top)))


def successor(z0, k):
    _, flips = heads(z0, k)
    best, best_score = None, -np.inf
    for m in range(M):
        p = 1.0 / (1.0 + np.exp(-flips[m]))
        alpha = (1 - z0) * p + z0 * (1 - p)
        mode = (alpha > 0.5).astype(np.float64)
        score = log_q(z0, mode, k)
        if score > best_score:
            best, best_score = mode, score
    return best


z0 = rng.integers(0, 2, (N, D)).astype(np.float64)
zt = rng.integers(0, 2, (N, D)).astype(np.float64)
labels = rng.integers(0, K, N)
scores = np.array([[log_q(z0[i], zt[i], k) for k in range(K)] for i in range(N)])
successors = np.array([[successor(z0[i], k) for k in range(K)] for i in range(N)])
loss = -np.mean([log_q(z0[i], zt[i], labels[i]) for i in range(N)]) / D

out = pathlib.Path(__file__).resolve().parents[2] / "data/reference/mixture_model.safetensors"
write(
    out,
    {
        **weights,
        "input.z0": z0,
        "input.zt": zt,
        "input.labels": labels.astype(np.float64),
        "expected.scores": scores,
        "expected.successors": successors.reshape(N * K, D),
        "expected.loss": np.array([loss]),
    },
)
print(f"wrote {out}: loss {loss:.6f}")
