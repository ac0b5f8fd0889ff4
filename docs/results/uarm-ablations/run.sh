#!/usr/bin/env bash
# The robot's absolute pushes on the twin (issue 44 item 3): one setting changed at a time from
# the paper's robot protocol (4 one-press episodes per epoch, 16 SAC updates, alpha 0.1, board and
# pen seen, a perfect twin), 2 seeds each, 5000 interactions. Training on the frozen binary of one
# clean commit (13631e6); its own evaluation at the end of training is bounded to one state and
# replaced. Each run is then evaluated by the frozen binary $EVAL (`seads uarm evaluate`: a fresh
# twin of the run's seed, as `uarm train` has done since 2026-11-29; evaluations resume, the
# twin replaying finished tasks): 20 boards per depth 1-5, re-planning, searches bounded by 2^20
# expanded states. A run with `evaluation-replan-tasks.jsonl` (written only by such an
# evaluation) is done.
# EVAL: the frozen 83717a6, from 2026-11-29 07:12 on the frozen a634bb8 (the same evaluations,
# faster: docs/results/screen-blocks/), from 2026-11-29 13:40 on the frozen ec1f66d (the same
# evaluations, remembering successors: docs/results/memo/).
# The new settings are all trained first (minutes each), then evaluated, the runs of highest
# coverage first; then the settings trained before, likewise. An agent that lacks moves makes up
# to 10 plans per failing task, each search after a deviation up to the 2^20 bound, so its
# evaluation takes hours where a complete agent's takes a minute. Resumable: rerun the script.
set -u
B=${SEADS:-/root/seads-frozen/13631e6/bin/seads}
E=${EVAL:?the frozen binary that evaluates, e.g. /root/seads-frozen/<commit>/bin/seads}
here=$(cd "$(dirname "$0")" && pwd)
# "paper" names its observation: a new run's default is the pen only since 3ab6aec (13631e6's
# default was the board and the pen, so the runs here are the same with either line).
new=(
  "updates-4|--updates-per-epoch 4"
  "episodes-16|--episodes-per-epoch 16"
  "alpha-0.3|--alpha 0.3"
  "updates-64|--updates-per-epoch 64"
  "episodes-1|--episodes-per-epoch 1"
  "late-reports-0.1|--late-reports 0.1"
)
# Trained before with their evaluation on the twin that training left: trained again (the same
# runs: the same frozen binary and seed) and evaluated on a fresh twin, after the new settings.
again=(
  "paper|--observe board-and-pen"
  "observe-board|--observe board"
  "observe-pen|--observe pen"
  "observe-nothing|--observe nothing"
  "alpha-0.01|--alpha 0.01"
  "tap-sd-5mm|--tap-sd-mm 5"
)
mkdir -p "$here/runs" "$here/logs"
train() { # SETTING...: train each setting's two seeds that have not trained
  for setting in "$@"; do
    name=${setting%%|*} opts=${setting#*|}
    for seed in 1 2; do
      run=$here/runs/$name-$seed log=$here/logs/$name-$seed.log
      [[ -f $run/evaluation-replan.json ]] && continue   # trained (its own evaluation written last)
      if [[ -f $run/config.toml ]]; then
        $B uarm train --port sim:$seed --resume --out $run --cores 1 --quiet --max-expanded 1 >> $log 2>&1
      else
        rm -rf $run
        $B uarm train --port sim:$seed --seed $seed $opts --out $run --cores 1 --quiet --max-expanded 1 >> $log 2>&1
      fi
      rc=$?; echo "$(date +%H:%M) $name-$seed trained, exit $rc" >> $here/done.log
    done
  done
}
evaluate() { # SETTING...: evaluate their trained runs, the highest final coverage first
  local runs=()
  for setting in "$@"; do
    for seed in 1 2; do
      m=$here/runs/${setting%%|*}-$seed/metrics.jsonl
      [[ -f $m ]] && runs+=("$(tail -1 $m | grep -o '"skill_coverage":[0-9.]*' | cut -d: -f2) $(dirname $m)")
    done
  done
  for run in $(printf '%s\n' "${runs[@]}" | sort -k1,1 -g -r | cut -d' ' -f2); do
    name=$(basename $run) seed=${run##*-}
    [[ -f $run/evaluation-replan-tasks.jsonl ]] && continue
    $E uarm evaluate --port sim:$seed --run $run --quiet --max-expanded 1048576 >> $here/logs/$name.log 2>&1
    rc=$?; echo "$(date +%H:%M) $name evaluated, exit $rc" >> $here/done.log
  done
}
train "${new[@]}"
evaluate "${new[@]}"
train "${again[@]}"
evaluate "${again[@]}"
