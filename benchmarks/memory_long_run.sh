#!/usr/bin/env bash
# Resident memory over a long threaded run: a rendered RGB-D sequence of FRAMES frames (default
# 3000: a loop of FRAMES - 300 frames, then 300 more over ground already mapped, where the map
# should stop growing), 320x240, run in threaded mode.
#
# Usage: benchmarks/memory_long_run.sh [FRAMES]
#   ORBIS the binary (default build/release/orbis); WORK a scratch folder (default: a temporary one)
#   CHECKPOINTS the frame counts of the shorter runs (default "500 1000 1500 2000 2500")
# 1. The full run, VmRSS of the orbis process sampled every 0.5 s (/proc/PID/status) into
#    WORK/rss.tsv: the curve over time, and the peak (VmHWM).
# 2. The same sequence cut at each checkpoint (--max-frames): keyframes and map points at the end,
#    and the resident memory at the end of tracking (the last sample before the final full BA
#    and the output writing, which allocate for the run's end only). Resident memory per
#    keyframe and per map point come from a least-squares fit RSS = base + a * keyframes; the
#    ratio to points is reported alike (keyframes and points grow together here, so the two
#    are one figure seen two ways: the memory of the map per keyframe, or per point).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
frames=${1:-3000}
orbis=${ORBIS:-$root/build/release/orbis}
work=${WORK:-$(mktemp -d)}
checkpoints=${CHECKPOINTS:-"500 1000 1500 2000 2500"}
mkdir -p "$work"
seq=$work/long
[[ -f $seq/settings.yaml ]] || "$orbis" synth "$seq" --frames $((frames - 300)) --extra 300 --width 320 --height 240 \
  --fx 250 --noise 4 --seed 23 --threads 2 >/dev/null

# Runs orbis on the first N frames (0: all) and samples its memory; prints "N keyframes points
# rss_at_end_of_tracking_kB peak_kB seconds tracked".
run() {
  local n=$1 out=$work/run_$1
  rm -rf "$out"
  "$orbis" run tum "$seq" --settings "$seq/settings.yaml" --max-frames "$n" --out "$out" >"$out.log" 2>&1 &
  local pid=$! t0=$SECONDS peak=0
  : > "$out.rss"
  while [[ -r /proc/$pid/status ]]; do
    local rss hwm
    rss=$(awk '/^VmRSS/ {print $2}' /proc/$pid/status 2>/dev/null || true)
    hwm=$(awk '/^VmHWM/ {print $2}' /proc/$pid/status 2>/dev/null || true)
    [[ -n $rss ]] && printf '%s\t%s\n' "$(date +%s.%N)" "$rss" >>"$out.rss"
    [[ -n $hwm ]] && peak=$hwm
    sleep 0.5
  done
  wait $pid
  python3 - "$out" "$n" "$peak" $((SECONDS - t0)) <<'PY'
import json, sys
out, n, peak, seconds = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
r = json.load(open(out + "/report.json"))
samples = [int(l.split()[1]) for l in open(out + ".rss") if l.strip()]
# End of tracking: the sample before the memory of the run's end (final BA, outputs) shows up;
# the median of the last 5% of the samples before the last two seconds.
body = samples[:-4] if len(samples) > 8 else samples
tail = sorted(body[-max(1, len(body) // 20):])
print(n, r["keyframes"], r["map_points"], tail[len(tail) // 2], peak, seconds, r["frames_tracked"])
PY
}

echo "full run: $frames frames, threaded" >&2
run 0 | tee "$work/full.txt"
cp "$work/run_0.rss" "$work/rss.tsv"
: > "$work/checkpoints.txt"
for n in $checkpoints; do run "$n" | tee -a "$work/checkpoints.txt"; done
read -r _ kf pts rss peak secs tracked < "$work/full.txt"
echo "$frames $kf $pts $rss $peak $secs $tracked" >> "$work/checkpoints.txt"
python3 - "$work/checkpoints.txt" "$work/rss.tsv" <<'PY'
import sys
rows = [list(map(float, l.split())) for l in open(sys.argv[1]) if l.strip()]
print(f"{'frames':>7} {'keyframes':>9} {'points':>7} {'RSS MB':>7} {'peak MB':>8} {'s':>5} {'tracked':>7}")
for n, kf, pts, rss, peak, secs, tracked in rows:
    print(f"{int(n):7d} {int(kf):9d} {int(pts):7d} {rss / 1024:7.1f} {peak / 1024:8.1f} {int(secs):5d} {int(tracked):7d}")
def fit(xs, ys):
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    a = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    return a, my - a * mx
rss = [r[3] * 1024 for r in rows]
a, b = fit([r[1] for r in rows], rss)
c, d = fit([r[2] for r in rows], rss)
res = max(abs(y - (a * r[1] + b)) for r, y in zip(rows, rss))
print(f"RSS = {b / 2**20:.1f} MB + {a / 1024:.1f} kB per keyframe (largest residual {res / 2**20:.1f} MB)")
print(f"RSS = {d / 2**20:.1f} MB + {c:.0f} B per map point")
print(f"peak (VmHWM) of the full run: {max(r[4] for r in rows) / 1024:.1f} MB")
samples = [int(l.split()[1]) for l in open(sys.argv[2]) if l.strip()]
q = len(samples) // 10
print("full run, RSS by tenth of its duration, MB:", " ".join(f"{samples[min(i * q, len(samples) - 1)] / 1024:.0f}" for i in range(11)))
PY
