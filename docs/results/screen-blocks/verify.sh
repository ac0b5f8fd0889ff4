#!/usr/bin/env bash
# That the change moves no result: the same evaluation by the binary before the change and by the
# binary of the change, each on its own copy of a trained run, and their task files compared
# line for line with the search times left out.
#   docs/results/screen-blocks/verify.sh BEFORE AFTER RUN_DIR EVALUATE_ARGS...
# e.g. (the checks summary.md reports)
#   verify.sh $B $A runs/tap-sd-5mm-2 uarm evaluate --port sim:2 --max-expanded 1048576
#   verify.sh $B $A runs/late-reports-0.1-1 uarm evaluate --port sim:1 --boards 1 --max-expanded 1048576
#   verify.sh $B $A agents/seed-1 evaluate --replan --depths 7-7 --boards 20 --search both-ends --memory-limit 16
set -eu
before=${1:?}; after=${2:?}; run=${3:?}; shift 3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for which in before after; do
  mkdir "$work/$which"
  for f in checkpoints config.toml metrics.jsonl provenance.jsonl robot.toml; do
    [[ -e $run/$f ]] && cp -r "$run/$f" "$work/$which/"
  done
  bin=$before; [[ $which = after ]] && bin=$after
  /usr/bin/time -f "$which: %U s user" "$bin" "$@" --run "$work/$which" --quiet
done
python3 - "$work" <<'PY'
import glob, json, os, sys
work = sys.argv[1]
def tasks(which):
    files = sorted(glob.glob(os.path.join(work, which, "evaluation-*-tasks.jsonl")))
    out = []
    for path in files:
        for line in open(path):
            record = json.loads(line)
            record.pop("planning_s", None)
            out.append((os.path.basename(path), record))
    return out
before, after = tasks("before"), tasks("after")
assert before, "no task files written"
if before == after:
    print(f"identical: {len(before)} lines")
else:
    sys.exit("the task files differ")
PY
