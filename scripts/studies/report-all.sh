#!/usr/bin/env bash
# Makes every committed study's report again from the runs committed beside it, with the binary
# given (default: target/release/seads), so that each report shows what today's `seads report`
# computes (interval estimates included). The runs are read, never changed; only the report's
# own files (report.md, CSV tables, figures) are written.
#
#   bash scripts/studies/report-all.sh [SEADS_BINARY]
set -euo pipefail
cd "$(dirname "$0")/../.."
seads="${1:-target/release/seads}"
r=docs/results
report() { # OUT INPUT...
    local out="$1"; shift
    echo "report: $out"
    "$seads" report "$@" --out "$out" > /dev/null
}
# A study whose runs are one sweep under runs/ (the sweep's reference is the reference).
for study in arms-jaco arms-reacher baselines board-size board-size-948442b diayn init-check \
    more-skills reacher3 table1 table1-ten tileswap-agents vic-a634bb8; do
    sweep=$(find "$r/$study/runs" -mindepth 2 -maxdepth 2 -name sweep.json -printf '%h\n')
    report "$r/$study" $sweep
done
report "$r/jaco" "$r/jaco/runs/arms"
report "$r/deep-search" "$r/deep-search/runs/init-check"
report "$r/deep-search/agents-a58a2c4/report" "$r/deep-search/agents-a58a2c4/sweep"
# The TileSwapCursor baselines are tested against the VIC study's SEADS runs.
report "$r/baselines-tileswap" "$r/vic-a634bb8/runs/vic" "$r/baselines-tileswap/runs/baselines-tileswap" \
    --reference seads
# Runs outside a sweep: each is its own variant, named by its folder.
report "$r/uarm" "$r/uarm/runs"/*/
report "$r/uarm-ablations" "$r/uarm-ablations/runs"/*/
