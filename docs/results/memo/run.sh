#!/usr/bin/env bash
# The memory of successors (ec1f66d) against the binary before it (a634bb8): the same twin
# evaluations by both, each on its own copy of a trained run of `uarm-ablations`, task files
# compared line for line (search times left out), user CPU seconds of each
# (`../screen-blocks/verify.sh`). Writes verify.log here; then repeat.log: the last check four
# times more, the binaries' order alternating (on a machine shared with running studies one
# measurement varies by a tenth or more).
#   docs/results/memo/run.sh BEFORE AFTER RUNS_DIR
set -eu
before=${1:?the binary before}; after=${2:?the binary after}; runs=${3:?uarm-ablations runs}
here=$(cd "$(dirname "$0")" && pwd)
verify=$here/../screen-blocks/verify.sh
{
  for check in "updates-4-2|--port sim:2" "episodes-1-1|--port sim:1 --boards 1" \
               "episodes-16-2|--port sim:2 --boards 2"; do
    run=$runs/${check%%|*} args=${check#*|}
    echo "== ${check%%|*} uarm evaluate $args --max-expanded 1048576"
    # shellcheck disable=SC2086
    "$verify" "$before" "$after" "$run" uarm evaluate $args --max-expanded 1048576 2>&1
  done
} | tee "$here/verify.log"
for i in 1 2; do
  for order in "$before $after" "$after $before"; do
    # shellcheck disable=SC2086
    "$verify" $order "$runs/episodes-16-2" uarm evaluate --port sim:2 --boards 2 --max-expanded 1048576 2>&1
  done
done > "$here/repeat.log"
