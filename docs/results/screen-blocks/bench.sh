#!/usr/bin/env bash
# The successor function's cost before and after the screen works in blocks (the first layer's
# activations built per row as the screen reads them, its integers and activations in reused
# blocks of 1,024 rows): `seads plan-bench` (breadth-first search, the fitted 256×256 LightsOut
# model, one thread) with the binary before the change and the binary of the change, run in turn,
# twice each. Writes <before|after>-<round>.json here.
#   docs/results/screen-blocks/bench.sh BEFORE_BINARY AFTER_BINARY
set -eu
here=$(cd "$(dirname "$0")" && pwd)
before=${1:?the binary before the change}
after=${2:?the binary of the change}
for round in 1 2; do
  for which in before after; do
    bin=$before; [[ $which = after ]] && bin=$after
    "$bin" plan-bench --depths 5,7,8 --boards 3 --json > "$here/$which-$round.json.tmp"
    mv "$here/$which-$round.json.tmp" "$here/$which-$round.json"
  done
done
