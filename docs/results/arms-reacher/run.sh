#!/usr/bin/env bash
# Core A from 2026-11-29 on: the four Reacher cells (issue 48 item 2), seeds 1-3 (replaces
# chainA2.sh: each SEADS run is evaluated as soon as it has trained, and only SEADS runs are).
# Training by the study's frozen binary (90d8a6b), outside the sweep (arms-train/), so that no
# 2^22-state evaluation holds the core and restarts from scratch at each stop. A SEADS run is then
# evaluated by the frozen a58a2c4 binary, whose evaluations resume (planning only; the sweep's
# protocol: 20 boards per depth 1-5, 2^22 expanded states per search, most-likely plans). Task
# success is reported for the SEADS rows only (Table 1 gives the ablations' coverage), so a
# no-relabelling run is copied into the sweep without one (`seads report` leaves it out of the
# success table). Resumable: rerun this script (resuming a finished run is a no-op).
T=/root/seads-frozen/90d8a6b/bin/seads
E=/root/seads-frozen/a58a2c4/bin/seads
S=/root/seads-sweeps/arms-reacher/runs
W=/root/seads-sweeps/arms-train
cd /root/seads-sweeps
runs=(tileswap-reacher/seads/seed-1 tileswap-reacher/no-relabelling/seed-1)
for s in 2 3; do
  for c in lightsout-reacher/seads lightsout-reacher/no-relabelling tileswap-reacher/seads tileswap-reacher/no-relabelling; do
    runs+=($c/seed-$s)
  done
done
for r in "${runs[@]}"; do
  R=$W/$r
  if [ -f $R/metrics.jsonl ]; then
    A=(--resume $R)
  else
    rm -rf $R; mkdir -p $(dirname $R)
    # One shared core: SAC takes no second thread (thread counts do not change the numbers).
    sed 's/^sac_threads_alone = 2$/sac_threads_alone = 0/' $S/$r/config.toml > $R.toml
    A=(--config $R.toml --out $R)
  fi
  $T train "${A[@]}" --quiet >> $R.log 2>&1 || { echo "$(date +%H:%M) arms $r train exit $?" >> done.log; continue; }
  echo "$(date +%H:%M) arms $r trained" >> done.log
  case $r in
    */seads/*)
      for mode in replan plan-once; do
        [ -f $R/evaluation-$mode.json ] && continue
        [ $mode = replan ] && M=--replan || M=
        $E evaluate --run $R $M --quiet >> $R.eval.log 2>&1
      done
      echo "$(date +%H:%M) arms $r evaluated exit $?" >> done.log ;;
  esac
  cp -a $R/. $S/$r/
done
