#!/usr/bin/env bash
# The paper's planner (the first plan found; no avoiding of failed skills) on copies of finished
# ablation runs, the same 100 boards and budget as their own evaluation.
set -u
B=/root/seads-frozen/13631e6/bin/seads
here=/root/seads-sweeps/uarm-ablations
for name in paper-2 observe-board-1 observe-pen-1 paper-1 observe-board-2; do
  src=$here/runs/$name
  [[ -f $src/evaluation-replan.json ]] || continue
  d=$here/first-found/$name
  [[ -f $d/evaluation-replan.json ]] && continue
  rm -rf $d; cp -r $src $d; rm -f $d/evaluation-replan* $d/task.lock
  seed=${name##*-}
  $B uarm evaluate --port sim:$seed --run $d --plan first-found --max-expanded 1048576 --quiet >> $here/first-found.log 2>&1
done
