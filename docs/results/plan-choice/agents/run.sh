#!/usr/bin/env bash
# Both plan choices on the init-check SEADS agents (seeds 1-5, 10^5 steps), re-planning, the
# standard 20 test boards per depth 1-5, 2^20 expanded states per search, binary of 5baf3bc.
set -u
B=/root/seads-frozen/5baf3bc/bin/seads
P=/root/seads-sweeps/plan-compare
for s in 1 2 3 4 5; do
  for c in most-likely first-found; do
    d=$P/$c/seed-$s
    [[ -f $d/evaluation-replan.json && -f $d/.done ]] && continue
    rm -rf "$d"; mkdir -p "$P/$c"
    cp -r /root/seads-sweeps/init-check/runs/lightsout-cursor/seads/seed-$s "$d"
    rm -f "$d"/evaluation-* "$d"/task.lock
    $B evaluate --run "$d" --replan --plan $c --boards 20 --max-expanded 1048576 --quiet --json > "$d.json" 2> "$d.log" && touch "$d/.done"
  done
done
