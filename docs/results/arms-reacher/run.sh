#!/usr/bin/env bash
# The four Reacher cells (issue 48 item 2): the runs named on the command line, in order, one
# shared core. Training by the study's frozen binary (90d8a6b) outside the sweep (arms-train/); a
# SEADS run is then evaluated by the frozen a58a2c4 binary in the sweep's protocol; each finished
# run is copied into the sweep. A run the sweep already holds finished (its budget trained and,
# for SEADS, both evaluations written) is skipped, so the whole list can be given on any machine.
# Resumable: rerun with the same list. `scripts/studies/resume.sh` starts it.
F=${SEADS_FROZEN:-$HOME/seads-frozen}
T=$F/90d8a6b/bin/seads
E=$F/a58a2c4/bin/seads
D=${SEADS_SWEEPS:-/root/seads-sweeps}
S=$D/arms-reacher/runs
W=$D/arms-train
cd "$D" || exit 2
# Whether the run folder $1 holds its whole budget of steps.
trained() {
  python3 - "$1" <<'PY'
import json, pathlib, sys, tomllib
run = pathlib.Path(sys.argv[1])
try:
    budget = tomllib.loads((run / "config.toml").read_text())["env_steps"]
    last = (run / "metrics.jsonl").read_text().strip().splitlines()[-1]
    sys.exit(0 if json.loads(last)["env_steps"] >= budget else 1)
except (OSError, KeyError, IndexError, ValueError):
    sys.exit(1)
PY
}
for r in "$@"; do
  case $r in
    */seads/*) evals=(evaluation-replan.json evaluation-plan-once.json) ;;
    *) evals=() ;;
  esac
  done_in_sweep=1
  trained "$S/$r" || done_in_sweep=0
  for e in "${evals[@]}"; do [ -f "$S/$r/$e" ] || done_in_sweep=0; done
  [ $done_in_sweep = 1 ] && continue
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
