#!/usr/bin/env bash
# The rendered room loop seen three ways, run monocular (deterministic): through a 180-degree
# Kannala-Brandt fisheye on the fisheye images directly (MonocularFisheye), the same fisheye
# frames undistorted to a pinhole first (the EuRoC layout read mono: OpenCV's valid-pixel pinhole),
# and a pinhole of the same image size and centre focal length; then the fisheye pair as stereo,
# rectified on load. Prints one row per run: frames tracked, keyframes, loops, ATE (Sim(3) for
# mono, SE(3) for stereo). docs/notes/2026-11-26-fisheye.md holds the figures.
# Usage: benchmarks/fisheye_loop.sh [SEED] (WORK=dir keeps the renders; ORBIS=path/to/orbis)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
orbis=${ORBIS:-$root/build/release/orbis}
work=${WORK:-$(mktemp -d)}
seed=${1:-1}
fov=${FOV:-180}
common=(--frames 300 --extra 75 --width 640 --height 480 --noise 4 --seed "$seed" --threads 2)
mkdir -p "$work"

[[ -f $work/fish_tum/settings_mono.yaml ]] || "$orbis" synth "$work/fish_tum" --camera fisheye --fov "$fov" "${common[@]}" >/dev/null
[[ -f $work/fish_euroc/settings.yaml ]] || "$orbis" synth "$work/fish_euroc" --layout euroc --camera fisheye --fov "$fov" "${common[@]}" >/dev/null
# The pinhole with the fisheye's focal length at the centre (the same angular resolution there).
fx=$(python3 -c "import re; print(re.search(r'Camera.fx: ([0-9.e+-]+)', open('$work/fish_tum/settings_mono.yaml').read()).group(1))")
[[ -f $work/pinhole_tum/settings_mono.yaml ]] || "$orbis" synth "$work/pinhole_tum" --fx "$fx" "${common[@]}" >/dev/null

row() {  # NAME REPORT.json
  python3 - "$1" "$2" <<'PY'
import json, sys
r = json.load(open(sys.argv[2]))
ate = r["ate"]
ate_text = "-" if ate is None else f"{ate['rmse'] * 1000:.1f} mm ({ate['alignment']})"
print(f"{sys.argv[1]:<34} tracked {r['frames_tracked']}/{r['frames']}  keyframes {r['keyframes']}"
      f"  loops {len(r['loops'])}  ATE {ate_text}")
PY
}

"$orbis" run tum "$work/fish_tum" --sensor mono --settings "$work/fish_tum/settings_mono.yaml" --deterministic \
  --out "$work/out_fisheye" --json >"$work/fisheye.json"
row "fisheye ${fov} deg, on the fisheye" "$work/out_fisheye/report.json"
"$orbis" run euroc "$work/fish_euroc" --sensor mono --deterministic --out "$work/out_undistorted" --json >"$work/undistorted.json"
row "fisheye ${fov} deg, undistorted first" "$work/out_undistorted/report.json"
"$orbis" run tum "$work/pinhole_tum" --sensor mono --settings "$work/pinhole_tum/settings_mono.yaml" --deterministic \
  --out "$work/out_pinhole" --json >"$work/pinhole.json"
row "pinhole fx ${fx}" "$work/out_pinhole/report.json"
"$orbis" run euroc "$work/fish_euroc" --sensor stereo --deterministic --out "$work/out_stereo" --json >"$work/stereo.json"
row "fisheye pair, rectified stereo" "$work/out_stereo/report.json"
