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
#      chainS: the LightsOutJaco cells (experiments/arms-jaco.toml; each seed's no forward-model
#      relabelling run first), then five LightsOutCursor agents at 5·10⁵ steps
#      (experiments/fig-s7-agents.toml) and their deeper search (scripts/studies/fig-s7.sh), then
#      the Reacher's bold cells (experiments/arms-reacher-bold.toml), then the 13×13 board's seeds
#      1-3, at nice 10;
#      chainJ: the LightsOutJaco cells (the Jaco seeds' SEADS run first), the sliding puzzle with
#      the mixture skill model (experiments/sliding-mixture.toml), the Reacher's bold cells from
#      the far end, then the 13×13 board, at nice 5.
#    Each chain resumes the runs it had begun before it starts new ones (index_chain below).
#    The finished studies (the Reacher cells, VIC, the TileSwapCursor baselines, board sizes to
#    9×9, DIAYN) are committed under docs/results/ and run no more; git history holds their chains.
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
  "arms-jaco 73dac45 73dac45 experiments/arms-jaco.toml docs/results/arms-jaco/runs/arms-jaco"
  "fig-s7-agents d45d7e2 d45d7e2 experiments/fig-s7-agents.toml docs/results/fig-s7-agents/runs/fig-s7-agents"
  "arms-reacher-bold d45d7e2 d45d7e2 experiments/arms-reacher-bold.toml docs/results/arms-reacher-bold/runs/arms-reacher-bold"
  "sliding-mixture c943245 c943245 experiments/sliding-mixture.toml docs/results/sliding-mixture/runs/sliding-mixture"
  "board-size 948442b 948442b experiments/board-size.toml docs/results/board-size-948442b/runs/board-size"
)
# The last commit whose committed manifests and run configurations were in the layout the frozen
# binaries read: `seads migrate` rewrote them in the next.
LAYOUT=951086a
# The binaries the studies run, frozen from these clean commits in this order; a chain runs no
# other.
FROZEN=(73dac45 d45d7e2 c943245 948442b)

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
index_chain chainS "# The LightsOutJaco cells, each seed's no forward-model relabelling run first (issue 48 item 2,
# frozen 73dac45); then five LightsOutCursor agents at 5·10⁵ steps and their deeper search
# (Fig. S.7, issue 81 item 2.4, frozen d45d7e2; scripts/studies/fig-s7.sh, this chain only: a
# search may take 16 GiB); then the Reacher's bold cells (issue 81 item 2.2, frozen d45d7e2); then
# the 13×13 board, seeds 1-3 (issue 48 item 4, frozen 948442b; scripts/studies/resume.sh)." 10 "" \
  "73dac45 arms-jaco 1 0 3 2 5 4" "d45d7e2 fig-s7-agents 0 1 2 3 4" \
  "run bash $root/scripts/studies/fig-s7.sh $SEADS_SWEEPS/fig-s7-agents $SEADS_FROZEN/d45d7e2/bin/seads >> fig-s7.out 2>&1" \
  "d45d7e2 arms-reacher-bold 0 1 2 3 4 5" "948442b board-size 3 8 13"
index_chain chainJ "# The LightsOutJaco cells, each seed's SEADS run first (frozen 73dac45), then the sliding
# puzzle with the mixture skill model, seeds 1-3 (issue 80 item 3, frozen c943245), then the
# Reacher's bold cells from the far end (frozen d45d7e2), then the 13×13 board, seeds 3-1 (frozen
# 948442b; scripts/studies/resume.sh)." 5 "" \
  "73dac45 arms-jaco 0 1 2 3 4 5" "c943245 sliding-mixture 0 1 2" \
  "d45d7e2 arms-reacher-bold 5 4 3 2 1 0" "948442b board-size 13 8 3"
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
