#!/usr/bin/env bash
# Threaded runs with merges under a timeout (issue 32: no crash, no hang). Runs one rendered
# corridor-with-blackout folder (benchmarks/atlas_corridor.py makes them) N times, threaded as in
# real use (not --deterministic), each under `timeout`, and prints per run: exit status (124: the
# timeout hit), frames tracked, maps opened, merges, the frame of the first merge and the ATE.
#   benchmarks/atlas_threaded.sh rgbd|stereo|mono FOLDER [RUNS=20] [TIMEOUT_S=300] [ORBIS] [WORK]
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sensor=${1:?usage: atlas_threaded.sh rgbd|stereo|mono FOLDER [RUNS] [TIMEOUT_S] [ORBIS] [WORK]}
seq=${2:?usage: atlas_threaded.sh rgbd|stereo|mono FOLDER [RUNS] [TIMEOUT_S] [ORBIS] [WORK]}
runs=${3:-20}
limit=${4:-300}
orbis=${5:-$root/build/release/orbis}
work=${6:-/tmp/orbis_atlas_threaded/$sensor}
mkdir -p "$work"
case "$sensor" in
  rgbd) args=(tum "$seq" --settings "$seq/settings.yaml") ;;
  stereo) args=(euroc "$seq" --settings "$seq/settings.yaml") ;;
  mono) args=(tum "$seq" --settings "$seq/settings_mono.yaml" --sensor mono) ;;
  *) echo "atlas_threaded: expected rgbd, stereo or mono, got '$sensor'" >&2; exit 2 ;;
esac
failed=0
for i in $(seq 1 "$runs"); do
  out=$work/run$i
  rm -rf "$out"
  timeout "$limit" "$orbis" run "${args[@]}" --out "$out" >"$out.log" 2>&1
  status=$?
  ((status == 0)) || failed=$((failed + 1))
  summary=$(python3 - "$out/report.json" <<'EOF' 2>/dev/null || echo "no report"
import json, sys
r = json.load(open(sys.argv[1]))
merges = r.get("merges", [])
ate = r.get("ate")
ate_mm = f"{1000 * ate['rmse']:.1f}" if ate else "-"
print(f"tracked {r['frames_tracked']}/{r['frames']} maps {len(r.get('maps', [])) or 1} merges {len(merges)} "
      f"merge_frame {merges[0]['frame'] if merges else '-'} ate_mm {ate_mm}")
EOF
)
  echo "run $i exit $status $summary"
done
echo "$sensor: $runs runs, $failed with a non-zero exit"
