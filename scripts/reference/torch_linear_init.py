"""Statistics of PyTorch's default `nn.Linear` initialisation, for the skill models' layers.

The reference builds its forward model and VIC discriminator as plain `nn.Sequential`s of
`nn.Linear` layers, so their weights and biases start as PyTorch's default initialisation draws
them. seads draws its own numbers from its own seeded generator, so the test cannot compare values;
it compares distributions. This script draws the layers of the LightsOutCursor forward model
(50 -> 256 -> 256 -> 25: [z_0, onehot(k)] -> flip logits) and discriminator (75 -> 256 -> 256 -> 25:
[z_0, z_T, z_0 xor z_T] -> skill logits) with `torch.nn.Linear` under `SEEDS` seeds and writes,
per layer and per parameter (weight, bias), the pooled sample's size, extremes, mean, standard
deviation and quantiles.

Writes data/reference/torch_linear_init.json. Checked by
crates/seads-skillmodel/tests/reference.rs (`initial_weights_follow_pytorchs_linear`).

Run with the PyTorch that scripts/setup.sh installs (torch 2.13.0), in a scratch environment:
    python3 scripts/reference/torch_linear_init.py
"""

import json
import pathlib

import torch

SEEDS = 32
QUANTILES = [0.01, 0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 0.95, 0.99]
NETWORKS = {
    "forward_model": [50, 256, 256, 25],
    "discriminator": [75, 256, 256, 25],
}

torch.set_num_threads(1)


def stats(values: torch.Tensor) -> dict:
    v = values.double().flatten()
    return {
        "n": v.numel(),
        "min": v.min().item(),
        "max": v.max().item(),
        "mean": v.mean().item(),
        "std": v.std(unbiased=False).item(),
        "quantiles": torch.quantile(v, torch.tensor(QUANTILES, dtype=torch.float64)).tolist(),
    }


out = {"torch": torch.__version__, "seeds": SEEDS, "quantiles": QUANTILES, "layers": []}
for name, sizes in NETWORKS.items():
    for i, (fan_in, fan_out) in enumerate(zip(sizes[:-1], sizes[1:])):
        weights, biases = [], []
        for seed in range(SEEDS):
            torch.manual_seed(seed)
            layer = torch.nn.Linear(fan_in, fan_out)
            weights.append(layer.weight.detach().clone())
            biases.append(layer.bias.detach().clone())
        out["layers"].append(
            {
                "network": name,
                "layer": i,
                "fan_in": fan_in,
                "fan_out": fan_out,
                "weight": stats(torch.stack(weights)),
                "bias": stats(torch.stack(biases)),
            }
        )

path = pathlib.Path(__file__).resolve().parents[2] / "data" / "reference" / "torch_linear_init.json"
path.write_text(json.dumps(out, indent=1) + "\n")
print(f"wrote {path}")
