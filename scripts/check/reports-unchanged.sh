#!/usr/bin/env bash
# Do two binaries make the same reports of the committed studies? For a change that must not move
# a number (a new file layout with its `seads migrate`, a reader rewritten): every committed
# study's input (each sweep under docs/results, each run outside a sweep) is reported by OLD_BIN
# from OLD_TREE's docs/results and by NEW_BIN from NEW_TREE's, and the two report folders are
# compared file by file (report.md, the CSVs, the figures).
#   scripts/check/reports-unchanged.sh OLD_BIN OLD_TREE NEW_BIN NEW_TREE [OUT]
# OLD_TREE is typically a worktree of the commit before the change (`git worktree add`), OLD_BIN
# built there (it must find libtorch: its own target folder beside a .libtorch link, or
# LD_LIBRARY_PATH). Exit 0 when every report is the same; the differences are in OUT/diff.txt.
set -euo pipefail
if [[ $# -lt 4 ]]; then
  echo "usage: scripts/check/reports-unchanged.sh OLD_BIN OLD_TREE NEW_BIN NEW_TREE [OUT]" >&2
  exit 2
fi
old_bin=$(realpath "$1") old_tree=$(realpath "$2") new_bin=$(realpath "$3") new_tree=$(realpath "$4")
out=${5:-$(mktemp -d)}
mkdir -p "$out/old" "$out/new"
# The inputs, as the new tree has them: sweeps, and runs that lie in no sweep.
cd "$new_tree"
mapfile -t inputs < <( (find docs/results -name sweep.json -printf '%h\n'
  find docs/results -name config.toml -not -path '*/checkpoints/*' -printf '%h\n') | sort -u)
reported=0
for dir in "${inputs[@]}"; do
  p=$dir in_sweep=0
  while [[ $p != docs/results ]]; do p=$(dirname "$p"); [[ -f $p/sweep.json ]] && in_sweep=1; done
  [[ $in_sweep == 1 && ! -f $dir/sweep.json ]] && continue
  name=${dir//\//_}
  for side in old new; do
    if [[ $side == old ]]; then bin=$old_bin tree=$old_tree; else bin=$new_bin tree=$new_tree; fi
    (cd "$tree" && "$bin" report "$dir" --out "$out/$side/$name" > "$out/$side/$name.log" 2>&1) ||
      echo "exit $?" >> "$out/$side/$name.log"
  done
  reported=$((reported + 1))
done
if diff -r -x '*.log' "$out/old" "$out/new" > "$out/diff.txt"; then
  echo "the same reports from both binaries: $reported inputs ($out)"
else
  echo "reports differ: $out/diff.txt" >&2
  exit 1
fi
