#!/usr/bin/env bash
# The deeper search (the paper's Fig. S.7): the five SEADS agents of the ten-seed LightsOutCursor
# study (seeds 6–10, whose checkpoints are at hand), 20 test boards per depth 6–10, with
# re-planning, 60 s per search. One evaluation per agent and depth, so that the study resumes
# where it stopped: an evaluation whose file exists is skipped. Depth-major, so that whole depth
# rows finish first. `JOBS` evaluations run at once (default 1: each search has a core). While
# the file `$sweep/deep-search.pause` exists, no new evaluation starts (the running ones finish),
# so that a benchmark or a test run does not share the processor with a timed search.
# Afterwards `seads report sweeps/table1-ten …` adds the deep-search table.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sweep=${SWEEP:-$root/sweeps/table1-ten}
seads=${SEADS:-$root/target/release/seads}
jobs=${JOBS:-1}
tasks=()
for depth in 6 7 8 9 10; do
  for seed in 6 7 8 9 10; do
    run=$sweep/runs/lightsout-cursor/seads/seed-$seed
    [[ -f $run/evaluation-replan-depths-$depth-$depth.json ]] || tasks+=("$run $depth")
  done
done
echo "deep search: ${#tasks[@]} evaluation(s) to run, $jobs at a time" >&2
[[ ${#tasks[@]} -gt 0 ]] || exit 0
printf '%s\n' "${tasks[@]}" | xargs -P "$jobs" -L 1 bash -c \
  'while [[ -e "$(dirname "$(dirname "$(dirname "$(dirname "$1")")")")/deep-search.pause" ]]; do sleep 5; done
   "$0" evaluate --run "$1" --replan --depths "$2-$2" --boards 20 --timeout 60 --quiet \
     && echo "deep search: $(basename "$1") depth $2 done" >&2' "$seads"
