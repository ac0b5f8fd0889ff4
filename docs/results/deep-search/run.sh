#!/usr/bin/env bash
# The deeper search (the paper's Fig. S.7) in its protocol: no clock, each search bounded by
# 16 GiB of memory (and the default 2^22 expanded states), 20 test boards per depth 6-10,
# re-planning, the most likely plan. Agents: the five SEADS LightsOutCursor runs of the
# init-check study (seeds 1-5, 10^5 steps, trained by the frozen binary of 21198f5, which trains
# as the current code does). Two searches, each on its own copy of the runs (evaluation files
# are not named by search): from both ends (depths 6-10), then breadth-first (depth-major, as
# far as it gets). One evaluation per agent and depth; a finished one is skipped.
set -u
B=${SEADS:-/root/seads-frozen/43568f0/bin/seads}
here=$(cd "$(dirname "$0")" && pwd)
src=/root/seads-sweeps/init-check/runs/lightsout-cursor/seads
for search in both-ends breadth; do
  for s in 1 2 3 4 5; do
    d=$here/$search/seed-$s
    if [[ ! -f $d/.copied ]]; then
      rm -rf "$d"; mkdir -p "$here/$search"
      cp -r "$src/seed-$s" "$d"
      rm -f "$d"/evaluation-* "$d"/task.lock "$d"/task.json
      touch "$d/.copied"
    fi
  done
done
for search in both-ends breadth; do
  for depth in 6 7 8 9 10; do
    for s in 1 2 3 4 5; do
      d=$here/$search/seed-$s
      [[ -f $d/evaluation-replan-depths-$depth-$depth.json ]] && continue
      "$B" evaluate --run "$d" --replan --depths "$depth-$depth" --boards 20 --search $search \
        --memory-limit 16 --quiet >> "$here/$search.log" 2>&1
      rc=$?; echo "$(date +%H:%M) $search seed $s depth $depth exit $rc" >> "$here/done.log"
    done
  done
done
