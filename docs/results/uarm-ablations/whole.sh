#!/usr/bin/env bash
# The two runs of run.sh that had been resumed (alpha-0.01-1 at epoch 1,000, late-reports-0.1-1 at
# epoch 100) by 13631e6, whose `uarm train --resume` started a new twin: trained again in one go
# by the same frozen binary and the same commands, then evaluated by $EVAL as run.sh evaluates
# (a fresh twin of the run's seed, 2^20 expanded states per search). The runs go to $OUT/runs;
# their data (without checkpoints) replace runs/<name>. Rerunning skips a trained run and resumes
# an evaluation from its journal; a run stopped during training is started afresh (13631e6 does
# not resume a twin run exactly).
set -u
B=${SEADS:-/root/seads-frozen/13631e6/bin/seads}
E=${EVAL:?the frozen binary that evaluates, e.g. /root/seads-frozen/ec1f66d/bin/seads}
out=${OUT:-/root/seads-sweeps/uarm-whole}
for setting in "alpha-0.01|--alpha 0.01" "late-reports-0.1|--late-reports 0.1"; do
  name=${setting%%|*} opts=${setting#*|} seed=1
  run=$out/runs/$name-$seed
  if [[ ! -f $run/evaluation-replan.json ]]; then
    rm -rf $run; mkdir -p $out/runs
    $B uarm train --port sim:$seed --seed $seed $opts --out $run --cores 1 --quiet --max-expanded 1 > $out/$name-$seed.train.log 2>&1
    echo "$(date +%H:%M) $name-$seed trained, exit $?" >> $out/done.log
  fi
  [[ -f $run/evaluation-replan-tasks.jsonl ]] && continue
  $E uarm evaluate --port sim:$seed --run $run --quiet --max-expanded 1048576 > $out/$name-$seed.eval.log 2>&1
  echo "$(date +%H:%M) $name-$seed evaluated, exit $?" >> $out/done.log
done
