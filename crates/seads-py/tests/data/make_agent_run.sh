#!/usr/bin/env bash
# How tests/data/agent-run and its evaluation-replan-tasks.jsonl were made (with the libtorch `seads`
# binary; run from the workspace root): a LightsOutCursor run with 64-wide networks, 30000
# steps, portable kernels (agent-run-train.toml), of which the test data keep the config and the
# last checkpoint's actor and forward model; then `seads evaluate` with re-planning on 5 boards
# per depth 1-5 and 2000 expanded states per search, whose tasks file the Python agent must
# repeat task for task.
set -euo pipefail
data=crates/seads-py/tests/data
tmp=$(mktemp -d)
seads=${SEADS:-target/release/seads}
"$seads" train --config "$data/agent-run-train.toml" --out "$tmp/run" --quiet
latest=$(cat "$tmp/run/checkpoints/latest")
rm -rf "$data/agent-run"
mkdir -p "$data/agent-run/checkpoints/$latest"
cp "$tmp/run/config.toml" "$data/agent-run/"
cp "$tmp/run/checkpoints/latest" "$data/agent-run/checkpoints/"
for f in config.toml origin.json forward_model.safetensors sac_actor.safetensors; do
  cp "$tmp/run/checkpoints/$latest/$f" "$data/agent-run/checkpoints/$latest/"
done
cp -r "$data/agent-run" "$tmp/eval"
"$seads" evaluate --run "$tmp/eval" --replan --boards 5 --max-expanded 2000 --quiet
cp "$tmp/eval/evaluation-replan-tasks.jsonl" "$data/agent-run/"
rm -rf "$tmp"
