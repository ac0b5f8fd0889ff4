#!/usr/bin/env bash
# Both plan choices on the more-skills agents (K = 30, 5·10^5 steps) that have finished training,
# re-planning, the standard 20 test boards per depth 1-5, 2^20 expanded states per search,
# frozen binary of 90d8a6b. A copy of each run per choice (evaluation files are not named by choice).
set -u
B=/root/seads-frozen/90d8a6b/bin/seads
P=/root/seads-sweeps/plan-compare-k30
R=/root/seads-sweeps/more-skills/runs/lightsout-cursor/more-skills
for s in "$@"; do
  [[ $($B sweep status /root/seads-sweeps/more-skills --json | python3 -c "import sys,json; d=json.load(sys.stdin); print([r['status'] for r in d['runs'] if r['seed']==$s][0])") == done ]] || continue
  for c in most-likely first-found; do
    d=$P/$c/seed-$s
    [[ -f $d/.done ]] && continue
    rm -rf "$d"; mkdir -p "$P/$c"
    cp -r $R/seed-$s "$d"
    rm -f "$d"/evaluation-* "$d"/task.lock
    $B evaluate --run "$d" --replan --plan $c --boards 20 --max-expanded 1048576 --quiet --json > "$d.json" 2> "$d.log" && touch "$d/.done"
  done
done
