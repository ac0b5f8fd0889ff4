#!/usr/bin/env bash
# Sets up and (re)starts the long studies in progress, on a machine that kept them or on a fresh
# one, in one command:
#   scripts/studies/resume.sh            set up what is missing, then start every chain not running
#   scripts/studies/resume.sh --setup    set up only (freeze binaries, lay out the sweeps)
#   scripts/studies/resume.sh --chains   write the chains (step 3) into $SEADS_SWEEPS only: no
#                                        set-up, nothing started (the tests read them)
# What it does, each step skipped where already done:
# 1. installs libtorch (scripts/setup.sh) and freezes the studies' binaries from their clean
#    commits (scripts/freeze.sh; ~10 minutes for the first, less for each other);
# 2. lays out each study's sweep under $SEADS_SWEEPS (default /root/seads-sweeps): `seads sweep
#    plan` of the manifest the committed sweep was planned from, as it was at $LAYOUT (the study's
#    manifest at its commit where none was committed then) by the study's frozen binary, then the
#    runs committed under docs/results/ laid over it (a finished run's files as they are, but its
#    config.toml, which stays the one the frozen binary planned: the committed one is in today's
#    layout, which the frozen binaries do not read; the others train);
# 3. writes the chains into $SEADS_SWEEPS (atomically: a running chain keeps its own copy) and
#    starts each that is not running, detached (setsid, nohup): two cores, one chain each, the
#    second running its studies one after another.
#      chainR: the Reacher cells (docs/results/arms-reacher/run.sh), at nice 5;
#      chainV, then chainB, then chainS: VIC, the TileSwapCursor baselines, board size, then
#      DIAYN against VIC and SEADS (experiments/diayn.toml), then the LightsOutJaco cells chainJ
#      has not reached (each seed's no forward-model relabelling run
#      first, SEADS's first on chainJ, so that the cores train a seed's pair together), then the
#      13×13 board's seeds 1-3 (chainJ takes them from the far end), at nice 10;
#      chainJ, once chainR is done: the board-size runs chainS has not reached (the 7×7 and 9×9
#      taken from the far end of its list, so that the two cores share them, then the 5×5 and the
#      spaced 5×5 the same way), then the LightsOutJaco cells (experiments/arms-jaco.toml), then
#      the 13×13 board, at nice 5.
#    Each chain resumes the runs it had begun before it starts new ones (index_chain below).
# Runs in progress resume from their checkpoints; runs lost with a machine start again.
# Progress: $SEADS_SWEEPS/done.log, `seads sweep status <sweep>` by the study's frozen binary.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
export SEADS_FROZEN=${SEADS_FROZEN:-$HOME/seads-frozen}
export SEADS_SWEEPS=${SEADS_SWEEPS:-/root/seads-sweeps}
case ${1:-} in
  "" | --setup | --chains) ;;
  *) echo "usage: scripts/studies/resume.sh [--setup | --chains]" >&2; exit 2 ;;
esac

# study, its frozen binary, the commit of its manifest, the manifest, its committed sweep
STUDIES=(
  "arms-reacher 90d8a6b 90d8a6b experiments/arms-reacher.toml docs/results/arms-reacher/runs/arms-reacher"
  "vic a634bb8 a634bb8 experiments/vic.toml docs/results/vic-a634bb8/runs/vic"
  "baselines-tileswap a634bb8 b2bfbff experiments/baselines-tileswap.toml docs/results/baselines-tileswap/runs/baselines-tileswap"
  "board-size 948442b 948442b experiments/board-size.toml docs/results/board-size-948442b/runs/board-size"
  "arms-jaco 73dac45 73dac45 experiments/arms-jaco.toml docs/results/arms-jaco/runs/arms-jaco"
  "diayn 4df69f9 4df69f9 experiments/diayn.toml docs/results/diayn/runs/diayn"
)
# The last commit whose committed manifests and run configurations were in the layout the frozen
# binaries read: `seads migrate` rewrote them in the next.
LAYOUT=951086a
# The binaries the studies run, frozen from these clean commits (a58a2c4 evaluates the Reacher
# runs); a chain runs no other.
FROZEN=(90d8a6b a58a2c4 a634bb8 948442b 73dac45 4df69f9)
# The Reacher runs in the order they train (finished ones are skipped).
REACHER=(
  lightsout-reacher/seads/seed-1 lightsout-reacher/seads/seed-2 lightsout-reacher/seads/seed-3
  lightsout-reacher/no-relabelling/seed-1 lightsout-reacher/no-relabelling/seed-3
  tileswap-reacher/seads/seed-1 tileswap-reacher/no-relabelling/seed-1
  tileswap-reacher/seads/seed-2 tileswap-reacher/no-relabelling/seed-2
  tileswap-reacher/seads/seed-3 tileswap-reacher/no-relabelling/seed-3
  lightsout-reacher/no-relabelling/seed-2
)

# Steps 1 and 2.
prepare() {
  # 1. libtorch (once per machine), then the frozen binaries.
  "$root/scripts/setup.sh"
  "$root/scripts/freeze.sh" "${FROZEN[@]}"

  # 2. The sweeps.
  mkdir -p "$SEADS_SWEEPS"
  for line in "${STUDIES[@]}"; do
    read -r name binary at manifest committed <<< "$line"
    sweep=$SEADS_SWEEPS/$name
    [[ -f $sweep/sweep.json ]] && continue
    echo "resume: laying out $sweep"
    rm -rf "$sweep.new"
    # Planned from the manifest the committed sweep was planned from (for a sweep not committed
    # yet, the study's manifest as it was at its commit), then the committed runs laid over it.
    if ! git -C "$root" show "$LAYOUT:$committed/manifest.toml" \
      > "$SEADS_SWEEPS/$name.manifest.toml" 2> /dev/null; then
      git -C "$root" show "$at:$manifest" > "$SEADS_SWEEPS/$name.manifest.toml"
    fi
    "$SEADS_FROZEN/$binary/bin/seads" sweep plan "$SEADS_SWEEPS/$name.manifest.toml" \
      --out "$sweep.new" > /dev/null
    if [[ -d $root/$committed/runs ]]; then
      tar -C "$root/$committed/runs" --exclude=config.toml -cf - . | tar -C "$sweep.new/runs" -xf -
    fi
    mv "$sweep.new" "$sweep"
  done
}
if [[ ${1:-} == --chains ]]; then mkdir -p "$SEADS_SWEEPS"; else prepare; fi
[[ ${1:-} == --setup ]] && exit 0

# 3. The chains.
write() { # name, then the script's text on standard input
  cat > "$SEADS_SWEEPS/$1.new" && mv "$SEADS_SWEEPS/$1.new" "$SEADS_SWEEPS/$1"
}
write arms-run.sh < "$root/docs/results/arms-reacher/run.sh"
write chainR.sh <<EOF
#!/usr/bin/env bash
# The Reacher cells (issue 48 item 2), one core (scripts/studies/resume.sh).
cd "$SEADS_SWEEPS"
nice -n 5 bash arms-run.sh ${REACHER[*]}
EOF
write chainV.sh <<EOF
#!/usr/bin/env bash
# VIC on both Cursor boards (issue 48 item 3), frozen a634bb8, seed by seed (scripts/studies/resume.sh).
cd "$SEADS_SWEEPS"
for s in 1 2 3; do
  nice -n 10 "$SEADS_FROZEN/a634bb8/bin/seads" sweep run vic --seeds \$s --workers 1 --cores 1 --quiet >> vic.log 2>&1
  rc=\$?; echo "\$(date +%H:%M) vic seed \$s exit \$rc" >> done.log
done
EOF
write chainB.sh <<EOF
#!/usr/bin/env bash
# The TileSwapCursor baselines (issue 48 item 3), frozen a634bb8, after VIC (scripts/studies/resume.sh).
cd "$SEADS_SWEEPS"
while pgrep -f "bash chainV.sh" > /dev/null; do sleep 60; done
for s in 1 2 3; do
  nice -n 10 "$SEADS_FROZEN/a634bb8/bin/seads" sweep run baselines-tileswap --seeds \$s --workers 1 --cores 1 --quiet >> baselines.log 2>&1
  rc=\$?; echo "\$(date +%H:%M) baselines seed \$s exit \$rc" >> done.log
done
EOF
# A chain that trains (and evaluates) sweeps' runs index by index with frozen binaries, once the
# chains named have ended; a finished run is skipped, so is one another chain holds (its lock is
# taken: status "running"). Within a sweep it goes twice through its indices: first it resumes
# the runs that have begun (steps trained, not finished), then it takes the rest in order, so a
# restarted chain finishes what it had begun before it starts anything new. Arguments: the chain,
# its comment lines, the niceness, the chains to wait for (none: it starts at once), then one
# "commit sweep indices…" segment per sweep, in order.
index_chain() {
  local chain=$1 comment=$2 niceness=$3 waits=$4 wait="" w segment commit sweep indices
  shift 4
  for w in $waits; do
    wait+="${wait:+ || }pgrep -f \"bash $w.sh\" > /dev/null"
  done
  {
    cat <<EOF
#!/usr/bin/env bash
$comment
cd "$SEADS_SWEEPS"
while ${wait:-false}; do sleep 60; done
EOF
    for segment in "$@"; do
      read -r commit sweep indices <<< "$segment"
      cat <<EOF
B="$SEADS_FROZEN/$commit/bin/seads"
for pass in begun all; do
  for i in $indices; do
    read -r st steps < <(\$B sweep status $sweep --json | python3 -c "import sys, json; r = json.load(sys.stdin)['runs'][\$i]; print(r['status'], r['env_steps'])")
    case \$st in done | copied | running) continue ;; esac
    [[ \$pass == begun && \$steps == 0 ]] && continue
    nice -n $niceness \$B sweep task $sweep --index \$i --cores 1 >> $sweep.log 2>&1
    rc=\$?; echo "\$(date +%H:%M) $sweep index \$i exit \$rc" >> done.log
  done
done
EOF
    done
  } | write "$chain.sh"
}
index_chain chainS "# Board size (issue 48 item 4), frozen 948442b, after the baselines: 7×7 and 9×9 seeds 1-3, then
# 5×5 seeds 1-3, then the spaced 5×5 seeds 1-3; then DIAYN, VIC and SEADS on both Cursor boards,
# planned with fitted models (issue 78 item 7, frozen 4df69f9), the 18 runs in the sweep's order;
# then the LightsOutJaco cells chainJ has not reached, each seed's pair from the other end of the
# pair (issue 48 item 2, frozen 73dac45); then the 13×13 board, seeds 1-3 (issue 48 item 4, if
# compute allows; scripts/studies/resume.sh)." 10 "chainB chainV" \
  "948442b board-size 1 2 6 7 11 12 0 5 10 4 9 14" \
  "4df69f9 diayn 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17" "73dac45 arms-jaco 1 0 3 2 5 4" \
  "948442b board-size 3 8 13"
index_chain chainJ "# On chainR's core once the Reacher cells are done: the board-size runs chainS has not reached,
# the 7×7 and 9×9 from the far end of its list, then the 5×5 and the spaced 5×5 the same way
# (issue 48 item 4, frozen 948442b), then the LightsOutJaco cells (issue 48 item 2, frozen
# 73dac45): SEADS and no forward-model relabelling, seed by seed; then the 13×13 board from the
# far end, seeds 3-1 (scripts/studies/resume.sh)." 5 chainR "948442b board-size 12 11 7 6 2 1 10 5 0 14 9 4" \
  "73dac45 arms-jaco 0 1 2 3 4 5" "948442b board-size 13 8 3"
[[ ${1:-} == --chains ]] && exit 0
cd "$SEADS_SWEEPS"
for chain in chainR chainV chainB chainS chainJ; do
  if pgrep -f "bash $chain.sh" > /dev/null; then
    echo "resume: $chain is running"
  else
    setsid nohup bash "$chain.sh" >> "$chain.out" 2>&1 < /dev/null &
    echo "resume: started $chain"
  fi
done
