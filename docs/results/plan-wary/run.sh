#!/usr/bin/env bash
# The wary plan choice (`--plan most-likely-wary`) on the deep-search agents (LightsOutCursor,
# 10^5 steps, trained again by a58a2c4; docs/results/deep-search/agents-a58a2c4), in the deep
# search's protocol: 20 test boards per depth, re-planning, from both ends, 16 GiB, 2^22 expanded
# states. Against those agents' most-likely evaluations (the same protocol, frozen a58a2c4). A
# copy of each agent (evaluation files are not named by plan choice). Resumable.
set -u
B=${SEADS:-/root/seads-frozen/f2591c9/bin/seads}
A=${AGENTS:-/root/seads-sweeps/deep-search/agents}
W=${OUT:-/root/seads-sweeps/plan-wary}
for job in 2:10 3:10 2:9 4:9 1:9 3:9 4:10 1:10; do
  s=${job%%:*}; depth=${job##*:}
  d=$W/seed-$s
  if [[ ! -f $d/.copied ]]; then
    rm -rf "$d"; mkdir -p "$W"
    mkdir "$d"; cp -r "$A/seed-$s/checkpoints" "$A/seed-$s"/{config.toml,metrics.jsonl,provenance.jsonl} "$d/"
    touch "$d/.copied"
  fi
  [[ -f $d/evaluation-replan-depths-$depth-$depth.json ]] && continue
  $B evaluate --run "$d" --replan --depths $depth-$depth --boards 20 --search both-ends \
    --memory-limit 16 --plan most-likely-wary --quiet >> "$W/run.log" 2>&1
  rc=$?; echo "$(date +%H:%M) wary seed $s depth $depth exit $rc" >> "$W/done.log"
done
# Depths 1-5 (the standard 20 test boards per depth), both choices, the same agents and protocol:
# whether the wary choice costs anything where repeated failures are rare. A copy per choice.
for s in 1 2 3 4; do
  for c in most-likely most-likely-wary; do
    d=$W/shallow/$c/seed-$s
    if [[ ! -f $d/.copied ]]; then
      rm -rf "$d"; mkdir -p "$d"
      cp -r "$A/seed-$s/checkpoints" "$A/seed-$s"/{config.toml,metrics.jsonl,provenance.jsonl} "$d/"
      touch "$d/.copied"
    fi
    [[ -f $d/evaluation-replan.json ]] && continue
    $B evaluate --run "$d" --replan --boards 20 --search both-ends --memory-limit 16 --plan $c \
      --quiet >> "$W/run.log" 2>&1
    rc=$?; echo "$(date +%H:%M) $c seed $s depths 1-5 exit $rc" >> "$W/done.log"
  done
done
