#!/usr/bin/env bash
# Threaded stress of the rendered RGB-D loop with loop closing: the sequence the loop tests render
# (seed 21, 300 frames + 75 over known ground, 320x240), run RUNS times in threaded mode (tracking,
# local mapping, loop closing and full BA on their own threads, so each run interleaves them
# differently). Each run must finish within TIMEOUT seconds (a deadlock would not) and exit 0.
#
# Usage: benchmarks/loop_stress.sh [RUNS] [TIMEOUT]      (defaults 20 and 300)
#   ORBIS   the binary (default build/release/orbis); WORK a scratch folder (default: a temporary one)
# Prints one row per run (exit code, seconds, keyframes, ATE) and the ATE spread: min, median,
# max, mean and standard deviation in mm. Exits non-zero if any run crashed, timed out or failed.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
runs=${1:-20}
limit=${2:-300}
orbis=${ORBIS:-$root/build/release/orbis}
work=${WORK:-$(mktemp -d)}
mkdir -p "$work"
seq=$work/loop_rgbd
[[ -f $seq/settings.yaml ]] || "$orbis" synth "$seq" --frames 300 --extra 75 --width 320 --height 240 --fx 250 \
  --noise 4 --seed 21 --threads 2 >/dev/null
failures=0
: > "$work/runs.tsv"
printf 'run\texit\tseconds\tkeyframes\tATE_mm\n'
for ((i = 1; i <= runs; ++i)); do
  out=$work/run$i
  rm -rf "$out"
  start=$(date +%s.%N)
  set +e
  timeout --signal=KILL "$limit" "$orbis" run tum "$seq" --settings "$seq/settings.yaml" --out "$out" >"$out.log" 2>&1
  rc=$?
  set -e
  seconds=$(python3 -c "import time; print(f'{time.time() - $start:.1f}')")
  read -r keyframes ate < <(python3 - "$out/report.json" <<'PY' 2>/dev/null || echo "- -"
import json, sys
r = json.load(open(sys.argv[1]))
print(r["keyframes"], f'{r["ate"]["rmse"] * 1000:.3f}' if r["ate"] else "-")
PY
)
  [[ $rc == 0 ]] || failures=$((failures + 1))
  [[ $rc == 137 ]] && echo "run $i: killed after ${limit} s (deadlock?)" >&2
  printf '%d\t%d\t%s\t%s\t%s\n' "$i" "$rc" "$seconds" "$keyframes" "$ate" | tee -a "$work/runs.tsv"
done
python3 - "$work/runs.tsv" <<'PY'
import statistics, sys
ates = [float(row.split("\t")[4]) for row in open(sys.argv[1]) if row.split("\t")[4].strip() not in ("-", "")]
if ates:
    print(f"ATE over {len(ates)} runs, mm: min {min(ates):.3f}  median {statistics.median(ates):.3f}  "
          f"max {max(ates):.3f}  mean {statistics.mean(ates):.3f}  sd {statistics.pstdev(ates):.3f}")
PY
echo "failed runs: $failures of $runs"
((failures == 0))
