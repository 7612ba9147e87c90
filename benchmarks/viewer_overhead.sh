#!/usr/bin/env bash
# Tracking time per frame with and without a connected live viewer, back to back.
#
# Usage: benchmarks/viewer_overhead.sh [SEQUENCE] [ROUNDS]
#   SEQUENCE  a TUM RGB-D folder (default ../shared/datasets/tum_fr3_teddy_200, TUM3 settings)
#   ROUNDS    how many rounds of (without, with) runs, alternating (default 3)
#   ORBIS     the binary (default build/release/orbis); VIEWER_CLIENT=curl|chromium: what reads
#             the stream (curl: the event stream only; chromium: the page, rendering headless,
#             which also puts the browser's own CPU on the machine).
#   SETTLE    seconds of rest before each run (default 2)
#   BROWSER_AS  user (default) or root: with chromium, how the browser is started. user: in a
#             session of its own (setsid) and without the right to raise its priority (setpriv
#             drops CAP_SYS_NICE), as a browser started from the desktop beside orbis in a
#             terminal. root: in the benchmark's session, with root's rights, under which Chromium
#             raises its browser and GPU processes to nice -8 (no desktop browser can). Either
#             way, on a 2-core machine shared with other jobs, tracking often came out faster with
#             the viewer open than without (medians of per-round ratios as root -6 % to -53 % over
#             six sets of 3-5 rounds; as user -53 % to +12 % over four sets of 5): runs there
#             measure the other jobs' scheduling more than the viewer; see the README.
# Runs threaded (as in real time). Per run, from report.json: medians of ORB extraction, of the
# tracking stages ("tracking: total") and of the observer's per-frame copy ("tracking: observer",
# only with the viewer), their sum; the CPU seconds of the whole orbis process; with Chromium,
# the CPU seconds of all its processes from loading the page to the end of the run
# (page_probe.py --metrics). On a shared, loaded machine single runs move by tens of percent: the
# summary compares the best run of each kind (the least disturbed), the medians of the runs, the
# median of each round's ratio (with / without the viewer, in the same round), and the median CPU
# seconds; each run with the viewer also prints what the viewer's publisher thread did.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sequence=${1:-$root/../shared/datasets/tum_fr3_teddy_200}
rounds=${2:-3}
orbis=${ORBIS:-$root/build/release/orbis}
baseline=${ORBIS_BASELINE:-}
client=${VIEWER_CLIENT:-curl}
port=${VIEWER_PORT:-18791}
settle=${SETTLE:-2}
browser_as=${BROWSER_AS:-user}
pacing=${PACING:-fast realtime}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

per_frame_ms() {  # report.json -> "extraction tracking observer sum run-seconds"
  python3 - "$1" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
t = r["timing_ms"]
m = lambda s: t[s]["median"] if s in t else 0.0
e, k, o = m("tracking: ORB extraction"), m("tracking: total"), m("tracking: observer")
print("%.3f %.3f %.3f %.3f %.2f" % (e, k, o, e + k + o, r["seconds"]))
PY
}

run() {  # run NAME BINARY [orbis args...]: CPU seconds (user + system) into NAME.cpu
  local name=$1 binary=$2
  shift 2
  sleep "$settle"  # the previous run's browser is still closing: every run starts as calm
  /usr/bin/time -f "%U %S" -o "$work/$name.time" "$binary" run tum "$sequence" \
    --settings "$root/examples/settings/TUM3.yaml" --out "$work/$name" "${pacing_args[@]}" "$@" >"$work/$name.log" 2>&1
  awk '{print $1 + $2}' "$work/$name.time" >"$work/$name.cpu"
}

with_viewer() {  # with_viewer NAME BINARY: the browser's CPU seconds into NAME.browser
  local name=$1 binary=$2
  rm -f "$work/$name.metrics" "$work/ready"
  local pid reader
  if [[ $client == chromium ]]; then
    # The browser is started first, as a person opens it before the run: its own start-up is not
    # the viewer's cost (it is left out of its CPU seconds too). It loads the page as soon as
    # orbis serves it and stays on it, rendering, until orbis has finished; SIGTERM then makes
    # it write what its processes used and close (--dump-dom would leave after the first
    # messages). It checks the page once a second, to add little of its own.
    local as_user=()  # neither forks: $! is the probe's pid
    [[ $browser_as == root ]] || as_user=(setsid setpriv --bounding-set -sys_nice --inh-caps -sys_nice)
    "${as_user[@]}" python3 "$root/tests/viewer/page_probe.py" "http://127.0.0.1:$port/" --until "window.orbisScene.live === false" \
      --timeout 300 --poll 1 --ready-file "$work/ready" --metrics "$work/$name.metrics" >/dev/null 2>&1 &
    reader=$!
    for _ in $(seq 300); do [[ -e $work/ready ]] && break; sleep 0.1; done
    run "$name" "$binary" --viewer "$port" &
    pid=$!
  else
    run "$name" "$binary" --viewer "$port" &
    pid=$!
    for _ in $(seq 50); do curl -s -m 1 -o /dev/null "http://127.0.0.1:$port/" && break; sleep 0.1; done
    curl -s -N -m 300 "http://127.0.0.1:$port/events" >"$work/events.txt" &
    reader=$!
  fi
  wait "$pid"
  kill "$reader" 2>/dev/null || true
  wait "$reader" 2>/dev/null || true
  if [[ -s $work/$name.metrics ]]; then
    python3 -c "import json,sys; m=json.load(open(sys.argv[1]))
print('%.2f' % (sum(m['cpu_seconds'].values()) - sum(m['cpu_seconds_before_page'].values())))" \
      "$work/$name.metrics" >"$work/$name.browser"
  else
    echo "-" >"$work/$name.browser"
  fi
}

kinds=(off on)
[[ -z $baseline ]] || kinds=(off base on)
# The sequence's own duration, first to last frame: what a realtime run cannot be shorter than.
duration=$(awk '!/^#/ && NF {if (first == "") first = $1; last = $1} END {printf "%.2f", last - first}' "$sequence/rgb.txt")
for mode in $pacing; do
case $mode in
  fast) pacing_args=() ;;
  realtime) pacing_args=(--realtime) ;;
  *) echo "PACING: fast or realtime, not $mode" >&2; exit 2 ;;
esac
echo "== pacing: $mode ($client$([[ $client != chromium ]] || echo ", browser as $browser_as"); load average $(cut -d' ' -f1-3 /proc/loadavg); the sequence lasts $duration s)"
printf "%-7s %11s %9s %9s %9s %8s %8s %10s\n" run extraction tracking observer "sum ms" "run s" "CPU s" "browser s"
for kind in "${kinds[@]}"; do : >"$work/$kind.sums"; done
for round in $(seq "$rounds"); do
  # Every other round in the reverse order (off on, on off, ...): a load that drifts during a
  # round, or a run that leaves the machine busier for the next, does not always favour one kind.
  order=("${kinds[@]}")
  (( round % 2 )) || order=($(printf '%s\n' "${kinds[@]}" | tac))
  for kind in "${order[@]}"; do
    case $kind in
      off) run off "$orbis"; echo "-" >"$work/off.browser" ;;
      base) with_viewer base "$baseline" ;;
      on) with_viewer on "$orbis" ;;
    esac
    read -r e k o sum secs < <(per_frame_ms "$work/$kind/report.json")
    echo "$sum $(cat "$work/$kind.cpu") $(cat "$work/$kind.browser")" >>"$work/$kind.sums"
    printf "%-7s %11s %9s %9s %9s %8s %8s %10s\n" "$kind $round" "$e" "$k" "$o" "$sum" "$secs" "$(cat "$work/$kind.cpu")" \
      "$(cat "$work/$kind.browser")"
    # What the viewer's own thread did (messages, bytes, its CPU): the cost that is not on tracking's.
    [[ $kind == off ]] || grep -h "^viewer: [0-9]" "$work/$kind.log" | sed 's/^/          /' || true
  done
done
python3 - "$work" "${kinds[@]}" <<'PY'
import statistics, sys
work, kinds = sys.argv[1], sys.argv[2:]
runs = {k: [l.split() for l in open("%s/%s.sums" % (work, k))] for k in kinds}
ms = {k: [float(r[0]) for r in runs[k]] for k in kinds}
cpu = {k: [float(r[1]) for r in runs[k]] for k in kinds}
label = {"base": "the baseline's viewer", "on": "the viewer"}
for k in kinds[1:]:
    for what, f in (("best", min), ("median", statistics.median)):
        a, b = f(ms["off"]), f(ms[k])
        print("%s tracking time per frame: %.2f ms without, %.2f ms with %s (%+.1f%%)"
              % (what, a, b, label[k], 100 * (b - a) / a))
    # Each run against the run without a viewer in its own round: the load of the moment cancels.
    ratios = [b / a for a, b in zip(ms["off"], ms[k])]
    print("per-round ratios with %s / without: %s" % (label[k], " ".join("%+.1f%%" % (100 * (r - 1)) for r in ratios)))
    print("median over the rounds of tracking time per frame with %s / without: %+.1f%%"
          % (label[k], 100 * (statistics.median(ratios) - 1)))
    a, b = statistics.median(cpu["off"]), statistics.median(cpu[k])
    print("median CPU of the orbis run: %.2f s without, %.2f s with %s (%+.1f%%)" % (a, b, label[k], 100 * (b - a) / a))
    browser = [float(r[2]) for r in runs[k] if r[2] != "-"]
    if browser:
        print("median CPU of the browser during a run with %s: %.2f s (all its processes, page load on)"
              % (label[k], statistics.median(browser)))
PY
[[ $client == chromium ]] || echo "(viewer client: curl; $(grep -c '^event:' "$work/events.txt" 2>/dev/null || echo 0) events in the last run)"
done
