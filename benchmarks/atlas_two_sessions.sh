#!/usr/bin/env bash
# Two sessions of one scene merged into one atlas (issue 32, "Must show" 2). Renders the corridor
# loop (seed 3, no blackout: 300 + 75 frames, 320x240), cuts it into part 1 = frames 0-149 and
# part 2 = frames 200-374 (part 2 starts about 4.5 m beyond where part 1 ended, in corridor part 1
# never saw, and comes back over part 1's start at its end), runs part 1 with --save-map, then
# part 2 with --load-map of part 1's atlas (and once more with --single-map), --deterministic, and
# scores both trajectories together against the one ground truth (one SE(3) alignment).
#   benchmarks/atlas_two_sessions.sh [ORBIS_BINARY] [WORK]
# Defaults: build/release/orbis, /tmp/orbis_atlas_two_sessions. Prints the figures of the note.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
orbis=${1:-$root/build/release/orbis}
work=${2:-/tmp/orbis_atlas_two_sessions}
mkdir -p "$work"
seq=$work/corridor_s3
if [[ ! -f $seq/rgb.txt ]]; then
  "$orbis" synth "$seq" --scene corridor --frames 300 --extra 75 --width 320 --height 240 --fx 250 --noise 4 \
    --seed 3 --threads 2 >/dev/null
fi
# cut FOLDER FIRST LAST: a TUM folder of frames FIRST..LAST (the images linked, not copied).
cut() {
  python3 - "$seq" "$1" "$2" "$3" <<'EOF'
import os, sys
seq, out, first, last = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
os.makedirs(out, exist_ok=True)
frame = lambda t: round((float(t) - 1.0) * 30.0)  # orbis synth: frame 0 at t = 1 s, 30 fps
for name in ("rgb.txt", "depth.txt", "groundtruth.txt"):
    with open(os.path.join(seq, name)) as src, open(os.path.join(out, name), "w") as dst:
        for line in src:
            if line.startswith("#") or first <= frame(line.split()[0]) <= last:
                dst.write(line)
for name in ("rgb", "depth"):
    if not os.path.exists(os.path.join(out, name)):
        os.symlink(os.path.join(seq, name), os.path.join(out, name))
EOF
}
cut "$work/part1" 0 149
cut "$work/part2" 200 374
settings=$seq/settings.yaml
rm -rf "$work/run1" "$work/run2" "$work/run2_single"
"$orbis" run tum "$work/part1" --settings "$settings" --deterministic --out "$work/run1" \
  --save-map "$work/part1.map" >"$work/run1.log" 2>&1
"$orbis" run tum "$work/part2" --settings "$settings" --deterministic --out "$work/run2" \
  --load-map "$work/part1.map" --save-map "$work/both.map" >"$work/run2.log" 2>&1
"$orbis" run tum "$work/part2" --settings "$settings" --deterministic --out "$work/run2_single" \
  --load-map "$work/part1.map" --single-map >"$work/run2_single.log" 2>&1
cat "$work/run1/trajectory.txt" "$work/run2/trajectory.txt" >"$work/both_trajectories.txt"
ate() { "$orbis" eval ate "$seq/groundtruth.txt" "$1" --json | python3 -c \
  "import json,sys; r=json.load(sys.stdin); print(f\"{1000*r['rmse']:.1f} mm RMSE over {r['matched']} poses\")"; }
python3 - "$work" <<'EOF'
import json, os, sys
work = sys.argv[1]
for run in ("run1", "run2", "run2_single"):
    r = json.load(open(os.path.join(work, run, "report.json")))
    line = f"{run}: {r['frames_tracked']}/{r['frames']} frames tracked, maps {len(r.get('maps', [])) or 1}"
    for m in r.get("maps", []):
        line += f"; map {m['id']} from frame {m['start_frame']}, {m['keyframes']} keyframes, merged into {m['merged_into']}"
    for m in r.get("merges", []):
        line += (f"; merge at frame {m['frame']} (keyframe {m['current_keyframe']} <-> {m['other_keyframe']}, "
                 f"{m['inliers']} inliers, {m['fused_points']} points fused, map {m['moved_map']} "
                 f"({m['moved_keyframes']} keyframes) moved into map {m['kept_map']}, {m['ms']:.0f} ms)")
    print(line)
EOF
echo "part 1 alone: $(ate "$work/run1/trajectory.txt")"
echo "part 2 alone: $(ate "$work/run2/trajectory.txt")"
echo "both, one alignment: $(ate "$work/both_trajectories.txt")"
echo "part 2 --single-map: $(ate "$work/run2_single/trajectory.txt")"
