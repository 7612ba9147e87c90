#!/usr/bin/env bash
# Tracking time per frame with and without a connected live viewer, back to back.
#
# Usage: benchmarks/viewer_overhead.sh [SEQUENCE] [PAIRS]
#   SEQUENCE  a TUM RGB-D folder (default ../shared/datasets/tum_fr3_teddy_200, TUM3 settings)
#   PAIRS     how many (without, with) pairs to run, alternating (default 1)
#   ORBIS     the binary (default build/release/orbis); VIEWER_CLIENT=curl|chromium: what reads
#             the stream (curl: the event stream only; chromium: the page, rendering headless).
# Runs threaded (as in real time). Per run, from report.json: medians of ORB extraction, of the
# tracking stages ("tracking: total") and of the observer's per-frame copy ("tracking: observer",
# only with the viewer), their sum, and the change of that sum against the run without.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sequence=${1:-$root/../shared/datasets/tum_fr3_teddy_200}
pairs=${2:-1}
orbis=${ORBIS:-$root/build/release/orbis}
client=${VIEWER_CLIENT:-curl}
port=${VIEWER_PORT:-18791}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

per_frame_ms() {  # report.json -> "extraction tracking observer sum"
  python3 - "$1" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["timing_ms"]
m = lambda s: t[s]["median"] if s in t else 0.0
e, k, o = m("tracking: ORB extraction"), m("tracking: total"), m("tracking: observer")
print("%.3f %.3f %.3f %.3f" % (e, k, o, e + k + o))
PY
}

run() {  # run NAME [orbis args...]
  local name=$1
  shift
  "$orbis" run tum "$sequence" --settings "$root/examples/settings/TUM3.yaml" --out "$work/$name" "$@" >/dev/null 2>&1
}

with_viewer() {
  run on --viewer "$port" &
  local pid=$! reader=""
  for _ in $(seq 50); do curl -s -m 1 -o /dev/null "http://127.0.0.1:$port/" && break; sleep 0.1; done
  if [[ $client == chromium ]]; then
    timeout 300 chromium --headless --disable-gpu --no-sandbox --window-size=1400,800 \
      --user-data-dir="$work/profile" --dump-dom "http://127.0.0.1:$port/?maps=100000" >/dev/null 2>&1 &
  else
    curl -s -N -m 300 "http://127.0.0.1:$port/events" >"$work/events.txt" &
  fi
  reader=$!
  wait "$pid"
  kill "$reader" 2>/dev/null || true
  wait "$reader" 2>/dev/null || true
}

changes=()
printf "%-8s %12s %12s %12s %12s %9s\n" run "extraction" "tracking" "observer" "sum (ms)" "change"
for pair in $(seq "$pairs"); do
  run off
  with_viewer
  read -r e0 k0 o0 s0 < <(per_frame_ms "$work/off/report.json")
  read -r e1 k1 o1 s1 < <(per_frame_ms "$work/on/report.json")
  printf "%-8s %12s %12s %12s %12s\n" "off $pair" "$e0" "$k0" "$o0" "$s0"
  change=$(python3 -c "print('%.1f' % (100 * ($s1 - $s0) / $s0))")
  changes+=("$change")
  printf "%-8s %12s %12s %12s %12s %8s%%\n" "on $pair" "$e1" "$k1" "$o1" "$s1" "$change"
done
echo "median change over $pairs pairs: $(printf '%s\n' "${changes[@]}" | sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}')%"

[[ $client == chromium ]] || echo "(viewer client: curl reading the event stream: $(grep -c '^event:' "$work/events.txt" 2>/dev/null || echo 0) events in the last run)"
