#!/usr/bin/env bash
# Sets up and (re)starts the long studies in progress, on a machine that kept them or on a fresh
# one, in one command:
#   scripts/studies/resume.sh            set up what is missing, then start every chain not running
#   scripts/studies/resume.sh --setup    set up only (freeze binaries, lay out the sweeps)
#   scripts/studies/resume.sh --chains   write the chains (step 3) into $SEADS_SWEEPS only: no
#                                        set-up, nothing started (the tests read them)
# What it does, each step skipped where already done:
# 1. installs libtorch (scripts/setup.sh) and freezes the studies' binaries from their clean
#    commits (scripts/freeze.sh; ~10 minutes for the first, less for each other), the study
#    furthest along first;
# 2. lays out each study's sweep under $SEADS_SWEEPS (default /root/seads-sweeps): `seads sweep
#    plan` of the manifest the committed sweep was planned from, as it was at $LAYOUT (the study's
#    manifest at its commit where none was committed then) by the study's frozen binary, then the
#    runs committed under docs/results/ laid over it (a finished run's files as they are, but its
#    config.toml, which stays the one the frozen binary planned: the committed one is in today's
#    layout, which the frozen binaries do not read; the others train);
# 3. writes the chains into $SEADS_SWEEPS (atomically: a running chain keeps its own copy) and
#    starts each that is not running, detached (setsid, nohup): two cores, one chain each, sharing
#    the sweeps from their two ends, so that the cores finish one study before the next:
#      chainS: DIAYN against VIC and SEADS (experiments/diayn.toml), then the LightsOutJaco cells
#      (experiments/arms-jaco.toml; each seed's no forward-model relabelling run first), then the
#      13×13 board's seeds 1-3, at nice 10;
#      chainJ: the same studies from the far end of each list (the Jaco seeds' SEADS run first),
#      at nice 5.
#    Each chain resumes the runs it had begun before it starts new ones (index_chain below).
#    The finished studies (the Reacher cells, VIC, the TileSwapCursor baselines, board sizes to
#    9×9) are committed under docs/results/ and run no more; git history holds their chains.
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
  "diayn 4df69f9 4df69f9 experiments/diayn.toml docs/results/diayn/runs/diayn"
  "arms-jaco 73dac45 73dac45 experiments/arms-jaco.toml docs/results/arms-jaco/runs/arms-jaco"
  "board-size 948442b 948442b experiments/board-size.toml docs/results/board-size-948442b/runs/board-size"
)
# The last commit whose committed manifests and run configurations were in the layout the frozen
# binaries read: `seads migrate` rewrote them in the next.
LAYOUT=951086a
# The binaries the studies run, frozen from these clean commits in this order; a chain runs no
# other.
FROZEN=(4df69f9 73dac45 948442b)

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
      if [[ $segment == "run "* ]]; then
        # A command of its own between the sweeps' segments.
        echo "${segment#run }"
        continue
      fi
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
index_chain chainS "# DIAYN, VIC and SEADS on both Cursor boards, planned with fitted models (issue 78 item 7,
# frozen 4df69f9), the 18 runs in the sweep's order; then the LightsOutJaco cells, each seed's
# no forward-model relabelling run first (issue 48 item 2, frozen 73dac45); then the 13×13
# board, seeds 1-3 (issue 48 item 4, frozen 948442b; scripts/studies/resume.sh)." 10 "" \
  "4df69f9 diayn $(seq -s ' ' 0 17)" "73dac45 arms-jaco 1 0 3 2 5 4" "948442b board-size 3 8 13"
index_chain chainJ "# The same studies as chainS from the far end of each list: DIAYN (frozen 4df69f9), then the
# LightsOutJaco cells, each seed's SEADS run first (frozen 73dac45), then the 13×13 board, seeds
# 3-1 (frozen 948442b; scripts/studies/resume.sh)." 5 "" \
  "4df69f9 diayn $(seq -s ' ' 17 -1 0)" "73dac45 arms-jaco 0 1 2 3 4 5" "948442b board-size 13 8 3"
[[ ${1:-} == --chains ]] && exit 0
cd "$SEADS_SWEEPS"
for chain in chainS chainJ; do
  if pgrep -f "bash $chain.sh" > /dev/null; then
    echo "resume: $chain is running"
  else
    setsid nohup bash "$chain.sh" >> "$chain.out" 2>&1 < /dev/null &
    echo "resume: started $chain"
  fi
done
