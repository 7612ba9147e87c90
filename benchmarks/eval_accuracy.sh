#!/usr/bin/env bash
# End-to-end accuracy sweep: deterministic ATE over the real slices and two rendered synthetic
# loops, each at three feature budgets, printed as the geometric mean per sequence with the
# three runs beside it. A single deterministic run moves by ~15 % with any small change (which
# keypoints win a quadtree node, which keyframe is culled), so compare changes with this, not
# with one run.
#   benchmarks/eval_accuracy.sh [LABEL]
# Environment: ORBIS (the orbis program, default build/release/orbis), ORBIS_DATA (default
# ../shared/datasets), WORK (scratch folder, default /tmp/orbis_eval). Appends to WORK/log.txt.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
orbis=${ORBIS:-$root/build/release/orbis}
data=${ORBIS_DATA:-$root/../shared/datasets}
work=${WORK:-/tmp/orbis_eval}
label=${1:-$(git -C "$root" rev-parse --short HEAD)}
mkdir -p "$work"

# Settings files with the budget replaced (one line each in the ORB-SLAM2 settings format).
budget() { sed "s/^ORBextractor.nFeatures: .*/ORBextractor.nFeatures: $2/" "$1"; }

# The synthetic loops of the loop-closing tests (320x240, noise 4), rendered once.
synth() {  # name seed [layout args]
  local dir=$work/$1
  [[ -f $dir/settings.yaml ]] || "$orbis" synth "$dir" --frames 300 --extra 75 --width 320 --height 240 \
    --fx 250 --noise 4 --seed "$2" --threads 2 "${@:3}" >/dev/null
}
synth synth_rgbd 21
synth synth_stereo 22 --layout euroc

run() {  # name kind path settings [extra]
  rm -rf "$work/out_$1"
  "$orbis" run "$2" "$3" --settings "$4" --deterministic --out "$work/out_$1" "${@:5}" >/dev/null 2>&1 || true
}
declare -A budgets=([teddy]="900 1000 1100" [kitti]="1800 2000 2200" [stereo]="700 800 900" [rgbd]="700 800 900")
for n in ${budgets[teddy]}; do
  budget "$root/examples/settings/TUM3.yaml" "$n" >"$work/tum_$n.yaml"
  run "teddy$n" tum "$data/tum_fr3_teddy_200" "$work/tum_$n.yaml" &
done
wait
for n in ${budgets[kitti]}; do
  budget "$root/examples/settings/KITTI04-12.yaml" "$n" >"$work/kitti_$n.yaml"
  run "kitti$n" kitti "$data/kitti_06_first51" "$work/kitti_$n.yaml" &
done
wait
for n in ${budgets[stereo]}; do
  budget "$work/synth_stereo/settings.yaml" "$n" >"$work/stereo_$n.yaml"
  budget "$work/synth_rgbd/settings.yaml" "$n" >"$work/rgbd_$n.yaml"
  run "stereo_closed$n" euroc "$work/synth_stereo" "$work/stereo_$n.yaml" &
  run "stereo_open$n" euroc "$work/synth_stereo" "$work/stereo_$n.yaml" --no-loop
  wait
  run "rgbd_closed$n" tum "$work/synth_rgbd" "$work/rgbd_$n.yaml" &
  run "rgbd_open$n" tum "$work/synth_rgbd" "$work/rgbd_$n.yaml" --no-loop
  wait
done

python3 - "$work" "$label" <<'PY' | tee -a "$work/log.txt"
import json, math, sys
work, label = sys.argv[1], sys.argv[2]
def ate(name):
    try:
        r = json.load(open(f"{work}/out_{name}/report.json"))
        return 1000 * r["ate"]["rmse"], r["frames_lost"]
    except (OSError, KeyError, ValueError):
        return float("nan"), -1
rows = [("teddy", "teddy", [900, 1000, 1100]), ("kitti06", "kitti", [1800, 2000, 2200]),
        ("stereo loop closed", "stereo_closed", [700, 800, 900]), ("stereo loop open", "stereo_open", [700, 800, 900]),
        ("rgbd loop closed", "rgbd_closed", [700, 800, 900]), ("rgbd loop open", "rgbd_open", [700, 800, 900])]
print(f"ATE mm, geometric mean over three budgets [{label}]")
for title, prefix, ns in rows:
    runs = [ate(f"{prefix}{n}") for n in ns]
    values = [a for a, _ in runs]
    mean = math.exp(sum(math.log(a) for a in values) / len(values)) if all(a > 0 for a in values) else float("nan")
    lost = "" if all(l == 0 for _, l in runs) else "  (frames lost or run failed)"
    print(f"  {title:20s} {mean:8.2f}   [{' / '.join(f'{a:.1f}' for a in values)}]{lost}")
PY
