#!/usr/bin/env bash
# Why portable runs differed between an Intel Xeon and an AMD EPYC, shown on one processor
# (docs/RESULTS.md, "Determinism across processors"; data in docs/results/determinism/).
#
# libtorch's Tensor::sqrt on the CPU is MKL's vmsSqrt, which refines the processor's rsqrtps
# estimate by one Newton step; Adam divides by that root every step. vml_sqrt.c replaces vmsSqrt
# by the same arithmetic from a chosen estimate. This script trains the demo's configuration for
# its first 300 epochs (22,000 steps) with
#   before         the commit before portable runs took the correctly rounded root (BEFORE)
#   before-native  the same with vml_sqrt.c on this processor's rsqrtps (must equal "before":
#                  the replacement computes what MKL computes)
#   before-intel   the same with the estimate table of Bochs's RSQRTPS emulation
#   head           this checkout
#   head-intel     this checkout with Bochs's estimates
# and compares them with the Intel Xeon's recorded demo run (git show BEFORE:docs/results/demo).
#
# Usage: scripts/determinism/rsqrt_emulation.sh [BOCHS_CHECKOUT] > summary.json
#   BOCHS_CHECKOUT  a clone of https://github.com/bochs-emu/Bochs (cloned into target/ if not
#                   given; only its table is read, into target/, never into the repository)
#   BEFORE_BIN      a release build of BEFORE to use instead of building it (target/determinism)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
scratch=$root/target/determinism
before=${BEFORE:-87650c5}
mkdir -p "$scratch"
cd "$root"

bochs=${1:-$scratch/bochs}
if [[ ! -f $bochs/bochs/cpu/sse_rcp.cc ]]; then
  git clone --quiet --depth 1 https://github.com/bochs-emu/Bochs "$bochs" >&2
fi
# The two 1024-entry tables (even exponents, then odd), one hexadecimal entry per line.
python3 - "$bochs/bochs/cpu/sse_rcp.cc" > "$scratch/intel-rsqrt.txt" <<'PYEOF'
import re, sys
text = open(sys.argv[1], encoding="utf-8").read()
for name in ("rsqrt_table0", "rsqrt_table1"):
    body = re.search(name + r"\[1024\]\s*=\s*\{(.*?)\};", text, re.S).group(1)
    entries = re.findall(r"0x[0-9a-fA-F]+", body)
    assert len(entries) == 1024, (name, len(entries))
    print("\n".join(entries))
PYEOF
gcc -O2 -ffp-contract=off -fPIC -shared -o "$scratch/libvmlsqrt.so" \
  scripts/determinism/vml_sqrt.c -lm

if [[ -z ${BEFORE_BIN:-} ]]; then
  git worktree remove --force "$scratch/before" 2>/dev/null || rm -rf "$scratch/before"
  git worktree prune
  git worktree add --quiet --detach "$scratch/before" "$before"
  ln -sfn "$root/.libtorch" "$scratch/.libtorch"  # the binary's rpath: $ORIGIN/../../.libtorch
  (cd "$scratch/before" && LIBTORCH=$root/.libtorch CARGO_TARGET_DIR=$scratch/target \
    cargo build --release --quiet -p seads-cli >&2)
  BEFORE_BIN=$scratch/target/release/seads
fi
cargo build --release --quiet -p seads-cli >&2
head_bin=$root/target/release/seads

git show "$before:docs/results/demo/metrics.jsonl" > "$scratch/xeon-demo.jsonl"
git show "$before:docs/results/demo/config.toml" | sed 's/^env_steps = .*/env_steps = 22000/' \
  > "$scratch/demo-300.toml"

train() {  # name binary [estimate table]
  local out=$scratch/runs/$1
  rm -rf "$out"
  if [[ $# -eq 2 ]]; then
    "$2" train --config "$scratch/demo-300.toml" --out "$out" --quiet >&2
  else
    LD_PRELOAD=$scratch/libvmlsqrt.so SEADS_RSQRT_TABLE=$3 \
      "$2" train --config "$scratch/demo-300.toml" --out "$out" --quiet >&2
  fi
}
train before "$BEFORE_BIN"
train before-native "$BEFORE_BIN" ""
train before-intel "$BEFORE_BIN" "$scratch/intel-rsqrt.txt"
train head "$head_bin"
train head-intel "$head_bin" "$scratch/intel-rsqrt.txt"

python3 scripts/determinism/compare_runs.py --last-epoch 300 \
  xeon-demo="$scratch/xeon-demo.jsonl" \
  before="$scratch/runs/before/metrics.jsonl" \
  before-native="$scratch/runs/before-native/metrics.jsonl" \
  before-intel="$scratch/runs/before-intel/metrics.jsonl" \
  head="$scratch/runs/head/metrics.jsonl" \
  head-intel="$scratch/runs/head-intel/metrics.jsonl"
