#!/usr/bin/env bash
# Tracking time per frame with and without a connected live viewer, back to back.
#
# Usage: benchmarks/viewer_overhead.sh [SEQUENCE] [PAIRS]
#   SEQUENCE  a TUM RGB-D folder (default ../shared/datasets/tum_fr3_teddy_200, TUM3 settings)
#   PAIRS     how many (without, with) pairs to run, alternating (default 3)
#   ORBIS     the binary (default build/release/orbis); VIEWER_CLIENT=curl|chromium: what reads
#             the stream (curl: the event stream only; chromium: the page, rendering headless,
#             which also puts the browser's own CPU on the machine).
# Runs threaded (as in real time). Per run, from report.json: medians of ORB extraction, of the
# tracking stages ("tracking: total") and of the observer's per-frame copy ("tracking: observer",
# only with the viewer), their sum; and the CPU seconds of the whole orbis process. On a shared,
# loaded machine single runs move by tens of percent: the summary compares the best run of each
# kind (the least disturbed), the medians of the runs, and the median CPU seconds; each run with
# the viewer also prints what the viewer's publisher thread did.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sequence=${1:-$root/../shared/datasets/tum_fr3_teddy_200}
pairs=${2:-3}
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

run() {  # run NAME [orbis args...]: CPU seconds (user + system) into NAME.cpu
  local name=$1
  shift
  /usr/bin/time -f "%U %S" -o "$work/$name.time" "$orbis" run tum "$sequence" \
    --settings "$root/examples/settings/TUM3.yaml" --out "$work/$name" "$@" >"$work/$name.log" 2>&1
  awk '{print $1 + $2}' "$work/$name.time" >"$work/$name.cpu"
}

with_viewer() {
  run on --viewer "$port" &
  local pid=$! reader=""
  for _ in $(seq 50); do curl -s -m 1 -o /dev/null "http://127.0.0.1:$port/" && break; sleep 0.1; done
  if [[ $client == chromium ]]; then
    # Stays on the page, rendering, until it shows the finished run (--dump-dom would leave after
    # the first messages).
    python3 "$root/tests/viewer/page_probe.py" "http://127.0.0.1:$port/" --until "window.orbisScene.live === false" \
      --timeout 300 >/dev/null 2>&1 &
  else
    curl -s -N -m 300 "http://127.0.0.1:$port/events" >"$work/events.txt" &
  fi
  reader=$!
  wait "$pid"
  kill "$reader" 2>/dev/null || true
  wait "$reader" 2>/dev/null || true
}

printf "%-6s %11s %9s %9s %9s %8s\n" run extraction tracking observer "sum ms" "CPU s"
: >"$work/off.sums"
: >"$work/on.sums"
for pair in $(seq "$pairs"); do
  for kind in off on; do
    if [[ $kind == off ]]; then run off; else with_viewer; fi
    read -r e k o sum < <(per_frame_ms "$work/$kind/report.json")
    echo "$sum $(cat "$work/$kind.cpu")" >>"$work/$kind.sums"
    printf "%-6s %11s %9s %9s %9s %8s\n" "$kind $pair" "$e" "$k" "$o" "$sum" "$(cat "$work/$kind.cpu")"
    # What the viewer's own thread did (messages, bytes, its CPU): the cost that is not on tracking's.
    [[ $kind == off ]] || grep -h "^viewer: [0-9]" "$work/on.log" | sed 's/^/         /' || true
  done
done
python3 - "$work/off.sums" "$work/on.sums" <<'PY'
import statistics, sys
off = [tuple(map(float, l.split())) for l in open(sys.argv[1])]
on = [tuple(map(float, l.split())) for l in open(sys.argv[2])]
best_off, best_on = min(s for s, _ in off), min(s for s, _ in on)
cpu_off, cpu_on = statistics.median(c for _, c in off), statistics.median(c for _, c in on)
print("best tracking time per frame: %.2f ms without, %.2f ms with the viewer (%+.1f%%)"
      % (best_off, best_on, 100 * (best_on - best_off) / best_off))
med_off, med_on = statistics.median(s for s, _ in off), statistics.median(s for s, _ in on)
print("median tracking time per frame: %.2f ms without, %.2f ms with the viewer (%+.1f%%)"
      % (med_off, med_on, 100 * (med_on - med_off) / med_off))
print("median CPU of the run: %.2f s without, %.2f s with the viewer (%+.1f%%)"
      % (cpu_off, cpu_on, 100 * (cpu_on - cpu_off) / cpu_off))
PY
[[ $client == chromium ]] || echo "(viewer client: curl; $(grep -c '^event:' "$work/events.txt" 2>/dev/null || echo 0) events in the last run)"
