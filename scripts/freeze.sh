#!/usr/bin/env bash
# Freezes the seads binary of each commit given: built once from that clean commit, outside the
# work tree, for a study's every run however often the work stops (issue 48 item 1; each run's
# provenance.jsonl names the commit). For each commit C:
#   $SEADS_FROZEN/src/C            a git worktree of C (kept: the build's sources)
#   $SEADS_FROZEN/C/bin/seads      the binary, written last (a stopped build leaves none)
# with one target folder for all, so that later commits rebuild only what changed, and
# $SEADS_FROZEN/.libtorch linked to this checkout's libtorch (scripts/setup.sh), which the
# binaries find through their rpath. A commit already frozen is skipped.
#   scripts/freeze.sh 90d8a6b a634bb8          (SEADS_FROZEN defaults to ~/seads-frozen)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
frozen=${SEADS_FROZEN:-$HOME/seads-frozen}
if [[ $# -eq 0 ]]; then
  echo "usage: scripts/freeze.sh COMMIT..." >&2
  exit 2
fi
for c in "$@"; do
  if ! git -C "$root" rev-parse --verify --quiet "$c^{commit}" > /dev/null; then
    echo "freeze: $c is not a commit of this repository" >&2
    exit 2
  fi
done
if [[ ! -e "$root/.libtorch/lib" ]]; then
  echo "freeze: no libtorch in this checkout: run scripts/setup.sh first" >&2
  exit 2
fi
mkdir -p "$frozen"
ln -sfn "$(readlink -f "$root/.libtorch")" "$frozen/.libtorch"
for c in "$@"; do
  bin=$frozen/$c/bin/seads
  [[ -x $bin ]] && { echo "freeze: $c already at $bin"; continue; }
  src=$frozen/src/$c
  git -C "$root" worktree remove --force "$src" 2> /dev/null || rm -rf "$src"
  git -C "$root" worktree prune
  git -C "$root" worktree add --detach --quiet "$src" "$c"
  ln -sfn "$frozen/.libtorch" "$src/.libtorch"
  if [[ -n $(git -C "$src" status --porcelain) ]]; then
    echo "freeze: the worktree of $c is not clean" >&2
    exit 1
  fi
  (cd "$src" && CARGO_TARGET_DIR=$frozen/target cargo build --release -p seads-cli --quiet)
  mkdir -p "$frozen/$c/bin"
  cp "$frozen/target/release/seads" "$bin.tmp"
  sync "$bin.tmp"
  mv "$bin.tmp" "$bin"
  "$bin" --version
done
