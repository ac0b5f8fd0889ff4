#!/usr/bin/env bash
# Whether late reports hurt through what the skills see: the late-reports setting of run.sh
# (10 % of the tablet's reports a press late) with skills that see the pen only, whose observation
# a late report cannot make stale (the board the robot believes lags the tablet's after a late
# report; the pen does not). Seeds 1 and 2, trained and evaluated as run.sh does, by the same
# frozen binaries. The runs go to $OUT/runs; their data (without checkpoints) go to
# runs/late-reports-0.1-pen-<seed>. Rerunning skips a trained run and resumes an evaluation from
# its journal; a run stopped during training is started afresh (13631e6 does not resume a twin
# run exactly).
set -u
B=${SEADS:-/root/seads-frozen/13631e6/bin/seads}
E=${EVAL:?the frozen binary that evaluates, e.g. /root/seads-frozen/ec1f66d/bin/seads}
out=${OUT:-/root/seads-sweeps/uarm-late-pen}
for seed in 1 2; do
  run=$out/runs/late-reports-0.1-pen-$seed
  if [[ ! -f $run/evaluation-replan.json ]]; then
    rm -rf $run; mkdir -p $out/runs
    $B uarm train --port sim:$seed --seed $seed --late-reports 0.1 --observe pen --out $run --cores 1 --quiet --max-expanded 1 > $run.train.log 2>&1
    echo "$(date +%H:%M) late-reports-0.1-pen-$seed trained, exit $?" >> $out/done.log
  fi
done
for seed in 1 2; do
  run=$out/runs/late-reports-0.1-pen-$seed
  [[ -f $run/evaluation-replan-tasks.jsonl ]] && continue
  $E uarm evaluate --port sim:$seed --run $run --quiet --max-expanded 1048576 > $run.eval.log 2>&1
  echo "$(date +%H:%M) late-reports-0.1-pen-$seed evaluated, exit $?" >> $out/done.log
done
