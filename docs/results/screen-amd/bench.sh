#!/usr/bin/env bash
# The 8-bit screen against float32 on one processor: `seads plan-bench` (breadth-first search,
# the fitted 256×256 LightsOut model, one thread) at depths 5 and 6, three boards each, with the
# screen forced on and with --float32, in turn. Usage: bench.sh SEADS_BINARY OUT_DIR
set -euo pipefail
seads=$1
out=$2
mkdir -p "$out"
grep -m1 'model name' /proc/cpuinfo > "$out/cpu.txt"
grep -m1 -o -w -E 'avx512_vnni|avx_vnni|amx_tile' /proc/cpuinfo | sort -u >> "$out/cpu.txt" || true
: > "$out/time.txt"
for mode in screen float32; do
  flag=()
  [ "$mode" = float32 ] && flag=(--float32)
  /usr/bin/time -a -o "$out/time.txt" -f "$mode %e s %U user" \
    "$seads" plan-bench --depths 5,6 --boards 3 "${flag[@]}" --json > "$out/$mode.json"
done
