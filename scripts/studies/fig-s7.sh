#!/usr/bin/env bash
# The deeper search (the paper's Fig. S.7) on the agents of experiments/fig-s7-agents.toml: for
# each finished run of the sweep, depths 6-10 with re-planning, 20 test boards per depth, from
# both ends, no clock, each search bounded by 16 GiB of memory and the default 2^22 expanded
# states, the most likely plan. Each (run, depth) is one evaluation file named by its protocol
# beside the run's standard ones; a finished one is skipped, so the script resumes.
#   bash scripts/studies/fig-s7.sh SWEEP BINARY
set -u
sweep=${1:?usage: fig-s7.sh SWEEP BINARY}
B=${2:?usage: fig-s7.sh SWEEP BINARY}
for depth in 6 7 8 9 10; do
  for run in "$sweep"/runs/lightsout-cursor/seads/seed-*; do
    [[ -f $run/task.json ]] && grep -q '"done"' "$run/task.json" || continue
    ls "$run"/evaluation-replan-depths-$depth-$depth-*both-ends*.json > /dev/null 2>&1 && continue
    nice -n 10 "$B" evaluate --run "$run" --replan --depths "$depth-$depth" --boards 20 \
      --search both-ends --memory-limit 16 --quiet >> "$sweep/fig-s7.log" 2>&1
    echo "$(date +%H:%M) fig-s7 $(basename "$run") depth $depth exit $?" >> "$sweep/fig-s7.done"
  done
done
