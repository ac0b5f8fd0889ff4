#!/usr/bin/env bash
# The four Reacher cells (issue 48 item 2), from 2026-11-29 (second machine): the runs named on the
# command line, in order, one shared core. Training by the study's frozen binary (90d8a6b) outside
# the sweep (arms-train/); a SEADS run is then evaluated by the frozen a58a2c4 binary in the
# sweep's protocol; each finished run is copied into the sweep. Resumable: rerun with the same list.
T=/root/seads-frozen/90d8a6b/bin/seads
E=/root/seads-frozen/a58a2c4/bin/seads
S=/root/seads-sweeps/arms-reacher/runs
W=/root/seads-sweeps/arms-train
cd /root/seads-sweeps
for r in "$@"; do
  R=$W/$r
  if [ -f $R/metrics.jsonl ]; then
    A=(--resume $R)
  else
    rm -rf $R; mkdir -p $(dirname $R)
    # One shared core: SAC takes no second thread (thread counts do not change the numbers).
    sed 's/^sac_threads_alone = 2$/sac_threads_alone = 0/' $S/$r/config.toml > $R.toml
    A=(--config $R.toml --out $R)
  fi
  $T train "${A[@]}" --quiet >> $R.log 2>&1 || { rc=$?; echo "$(date +%H:%M) arms $r train exit $rc" >> done.log; continue; }
  echo "$(date +%H:%M) arms $r trained" >> done.log
  case $r in
    */seads/*)
      for mode in replan plan-once; do
        [ -f $R/evaluation-$mode.json ] && continue
        [ $mode = replan ] && M=--replan || M=
        $E evaluate --run $R $M --quiet >> $R.eval.log 2>&1
      done
      rc=$?; echo "$(date +%H:%M) arms $r evaluated exit $rc" >> done.log ;;
  esac
  cp -a $R/. $S/$r/
done
