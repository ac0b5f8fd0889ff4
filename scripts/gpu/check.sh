#!/usr/bin/env bash
# The device check, run on the GPU test machine (../shared/gpu/README.md) in a copy of the
# repository with the binary that scripts/gpu/build.sh put at gpu/seads. It prints one table:
# - the planner: `plan-bench --hidden 256,256` at depths 7–12 on the GPU, and on the CPU's cores
#   (60 s per search; the first depth that hits it is the last);
# - training: one LightsOutCursor run of 10⁵ steps on the GPU beside the same run on one CPU
#   core, their steps/s and skill coverage;
# - devices: each run's checkpoint evaluated on the other device, and the errors a missing GPU
#   gives;
# - a population of 16 runs trained as one on the GPU (SAC on stacked weights there, the rest on
#   the CPU cores), its summed steps/s against the one-core run;
# - the golden configuration on this processor against the EPYC's (issue 32, item 10).
# What it measured goes to $OUT (default target/gpu-check): the JSON, the logs, the runs'
# metrics, provenance and config, table.txt, and all of it again as all.tgz (the device tool
# brings back only a few files per call); the runs themselves go to $RUNS. About 7 minutes on an
# H100 with 16 cores; every step has a time limit, so a hang cannot take the machine's lease.
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
seads=${SEADS:-$root/gpu/seads}
out=${OUT:-$root/target/gpu-check}
runs=${RUNS:-$root/target/gpu-runs}   # the training runs (checkpoints stay out of $out)
steps=${STEPS:-100000}
mkdir -p "$out" "$runs"
python=${PYTHON:-$(command -v python3)}
[[ -x /opt/torch/.venv/bin/python3 ]] && python=${PYTHON:-/opt/torch/.venv/bin/python3}
depths=${DEPTHS:-7,8,9,10,11,12}
# The binary finds libtorch (and through it the CUDA libraries) in the machine's PyTorch.
if torch_lib=$("$python" -c 'import os, torch; print(os.path.join(os.path.dirname(torch.__file__), "lib"))' 2>/dev/null); then
  export LD_LIBRARY_PATH=$torch_lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
fi
cores=$(nproc)
pin() { # pin CPUS COMMAND...: run on those cores, where taskset exists and there are 8 or more
  local cpus=$1; shift
  if command -v taskset >/dev/null && ((cores >= 8)); then taskset -c "$cpus" "$@"; else "$@"; fi
}
log() { echo "[$(date +%T)] $*" | tee -a "$out/check.log" >&2; }

log "machine: $(nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>&1 | head -1); $cores cores; $(uname -r)"
log "binary: $("$seads" --version 2>&1)"

# Devices that are not there: one line, exit 2, nothing written.
for device in cuda:99 tpu; do
  timeout 60 "$seads" train --env lightsout-cursor --out "$runs/refused" --device "$device" \
    > "$out/refused-${device//:/-}.txt" 2>&1
  echo "exit $?" >> "$out/refused-${device//:/-}.txt"
  log "train --device $device: $(tr '\n' ' ' < "$out/refused-${device//:/-}.txt")"
done
[[ -e $runs/refused ]] && log "ERROR: a refused device left $runs/refused behind"

# Training: the same run (the preset with one libtorch thread) on one CPU core (core 2) and on
# the GPU (cores 0-1 for its two training threads), on different cores. The CPU run takes
# longest and starts first; the planner runs on cores 3 and up meanwhile.
cat > "$out/train.toml" <<EOF
env = "lightsout-cursor"
seed = 1
env_steps = $steps
threads = 1
sac_threads_alone = 0
EOF
rm -rf "$runs/train-cuda" "$runs/train-cpu"
keep() { # keep RUN: its metrics, provenance and evaluations into $out
  for f in "$runs/$1"/{metrics.jsonl,provenance.jsonl,config.toml}; do
    [[ -f $f ]] && cp "$f" "$out/$1-$(basename "$f")"
  done
}
log "training $steps steps on one CPU core (core 2), in the background"
pin 2 timeout 450 "$seads" train --config "$out/train.toml" --out "$runs/train-cpu" --device cpu \
  --quiet > "$out/train-cpu.log" 2>&1 &
cpu_train=$!
free=$((cores > 4 ? cores - 3 : 1))
planner_cores=$((cores > 4 ? 3 : 0))-$((cores - 1))

log "plan-bench on the GPU ($free threads for the bookkeeping)"
pin "$planner_cores" timeout 150 "$seads" plan-bench --hidden 256,256 --depths "$depths" \
  --boards 2 --device cuda --threads "$free" --timeout 60 --json > "$out/plan-cuda.json" 2> "$out/plan-cuda.log"
log "plan-bench on the GPU: exit $?"

# The CPU planner on cores 3 and up, beside the GPU run on cores 0-1 (and the CPU run on 2).
log "plan-bench on $free CPU threads, in the background"
pin "$planner_cores" timeout 280 "$seads" plan-bench --hidden 256,256 --depths "$depths" \
  --boards 2 --device cpu --threads "$free" --timeout 60 --json > "$out/plan-cpu.json" 2> "$out/plan-cpu.log" &
cpu_plan=$!

log "training $steps steps on the GPU (cores 0-1)"
pin 0-1 timeout 330 "$seads" train --config "$out/train.toml" --out "$runs/train-cuda" --device cuda \
  --quiet > "$out/train-cuda.log" 2>&1
log "training on the GPU: exit $?"
keep train-cuda
wait "$cpu_plan"
log "plan-bench on the CPU: exit $?"
wait "$cpu_train"
log "training on one CPU core: exit $?"
keep train-cpu

# The one-thread figure of the CPU planner, alone on the machine.
log "plan-bench on one CPU thread, depth 7"
pin 3 timeout 90 "$seads" plan-bench --hidden 256,256 --depths 7 --boards 2 --device cpu \
  --threads 1 --json > "$out/plan-cpu-1.json" 2> "$out/plan-cpu-1.log"
log "plan-bench on one CPU thread: exit $?"

# Checkpoints across devices: each run's agent plans on the other device.
for pair in "train-cuda cpu" "train-cpu cuda"; do
  set -- $pair
  timeout 120 "$seads" evaluate --run "$runs/$1" --device "$2" --depths 1-2 --boards 2 \
    --timeout 10 --json > "$out/evaluate-$1-on-$2.json" 2> "$out/evaluate-$1-on-$2.log"
  log "evaluate $1 on $2: exit $? $(head -c 300 "$out/evaluate-$1-on-$2.json")"
done

# A population of 16 LightsOutCursor runs (seeds 1-16, the preset's settings, POP_STEPS steps
# each) trained as one on the GPU with the cores but two, against the one-core CPU run above (the
# issue's target: at least 25 times its steps/s, summed over the members). Meanwhile, on the last
# two cores, the golden configuration on this processor's CPU (data/golden/config.toml, portable
# numerics) with gpu/seads-cpu, which repeats the golden on the development machine's AMD EPYC
# (data/golden/libtorch-2.11/): whether a portable run is the same on this processor (issue 32,
# item 10).
pop_steps=${POP_STEPS:-10000}
pop_cores=$((cores > 4 ? cores - 2 : cores))
rm -rf "$runs/population" "$runs/golden"
cat > "$out/population.toml" <<EOF
name = "population-gpu"
environments = ["lightsout-cursor"]
seeds = [$(seq -s ', ' 1 16)]

[overrides]
env_steps = $pop_steps

[evaluation]
every = 0
last = false

[[variant]]
name = "seads"
EOF
golden=""
if [[ -x $root/gpu/seads-cpu ]] && ((cores > 4)); then
  log "the golden configuration on this CPU (cores $((cores - 2))-$((cores - 1))), in the background"
  pin "$((cores - 2))-$((cores - 1))" timeout 400 "$root/gpu/seads-cpu" train \
    --config "$root/data/golden/config.toml" --out "$runs/golden" --quiet > "$out/golden.log" 2>&1 &
  golden=$!
fi
"$seads" sweep plan "$out/population.toml" --out "$runs/population" > /dev/null
log "a population of 16 runs of $pop_steps steps on the GPU with $pop_cores cores"
start=$(date +%s%N)
# A thread per member on the pinned cores: members wait for each other every epoch, so 16 members
# on 14 threads would take two rounds per epoch where time-sharing the cores takes 16/14 of one.
pin "0-$((pop_cores - 1))" timeout 300 "$seads" sweep task "$runs/population" --index 0-15 \
  --cores 16 --device cuda --allow-dirty > "$out/population.log" 2>&1
log "population on the GPU: exit $?"
echo "{\"wall_s\": $((($(date +%s%N) - start) / 1000000))e-3, \"runs\": 16, \"steps_each\": $pop_steps, \"cores\": $pop_cores, \"threads\": 16}" \
  > "$out/population-wall.json"
for seed in $(seq 1 16); do
  cp "$runs/population/runs/lightsout-cursor/seads/seed-$seed/metrics.jsonl" \
    "$out/population-seed-$seed-metrics.jsonl" 2>/dev/null
done
if [[ -n $golden ]]; then
  wait "$golden"
  log "golden: exit $?"
  for f in metrics.jsonl provenance.jsonl; do cp "$runs/golden/$f" "$out/golden-$f" 2>/dev/null; done
fi
if [[ -x $root/gpu/numerics_fingerprint ]]; then
  MKL_CBWR=COMPATIBLE ATEN_CPU_CAPABILITY=avx2 timeout 60 "$root/gpu/numerics_fingerprint" \
    > "$out/golden-fingerprint.json" 2> "$out/golden-fingerprint.log"
  log "fingerprint: exit $?"
fi

"$python" "$root/scripts/gpu/table.py" "$out" | tee "$out/table.txt"
tar czf "$root/gpu-check.tgz" -C "$out" . && mv "$root/gpu-check.tgz" "$out/all.tgz"
