#!/usr/bin/env bash
# Screenshots of the live viewer page during runs, taken by headless Chromium:
#   loop_closure.png  a rendered RGB-D loop (orbis synth, 300 + 75 frames), top view, frozen as
#                     the page receives the map that holds the first loop closure (?loops=1: the
#                     page then closes its stream)
#   teddy_live.png    TUM fr3 teddy (real, RGB-D), once the page has shown frame 120
#   kitti_live.png    KITTI 06, first 51 frames (real, stereo), once it has shown frame 30
#   atlas_merge.png   the atlas (issue 32): a rendered RGB-D corridor loop with 30 black frames
#                     while the camera moves on (a second map opens), top view, frozen as the page
#                     receives the map that holds the first merge (?merges=1)
#   atlas_two_maps.png the same run before the merge, once the page has shown frame 250: two maps
#                     in their own colours, each in its own frame
# Each run is threaded, as in real time, with --viewer-wait; tests/viewer/page_probe.py drives
# headless Chromium over the DevTools protocol, waits for the condition, and shoots. It prints
# the page's scene (window.orbisScene): "live":true means the shot was taken during the run.
#
# Usage: benchmarks/viewer_screenshots.sh [OUT_DIR]   (default /tmp/orbis-viewer-screenshots)
#   ORBIS: the binary (default build/release/orbis); DATA: ../shared/datasets
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-/tmp/orbis-viewer-screenshots}
orbis=${ORBIS:-$root/build/release/orbis}
data=${DATA:-$root/../shared/datasets}
port=${VIEWER_PORT:-18771}
chromium=$(command -v chromium || command -v chromium-browser) || { echo "chromium not found" >&2; exit 1; }
mkdir -p "$out"
pid=""
trap '[[ -z $pid ]] || { kill -TERM $pid 2>/dev/null; wait $pid 2>/dev/null; } || true' EXIT

# shoot NAME QUERY CONDITION orbis-run-arguments...: starts the run with the viewer, loads the
# page with QUERY, waits until CONDITION (JavaScript) holds, saves NAME.png, stops the run.
shoot() {
  local name=$1 query=$2 condition=$3
  shift 3
  rm -rf "$out/$name"
  "$orbis" run "$@" --out "$out/$name" --viewer "$port" --viewer-wait >"$out/$name.log" 2>&1 &
  pid=$!
  for _ in $(seq 100); do curl -s -m 1 -o /dev/null "http://127.0.0.1:$port/" && break; sleep 0.1; done
  local scene
  scene=$(python3 "$root/tests/viewer/page_probe.py" "http://127.0.0.1:$port/?$query" --until "$condition" \
    --screenshot "$out/$name.png" --timeout 300 --chromium "$chromium") || true
  # The first signal ends the run; --viewer-wait then serves it until the next one.
  while kill -TERM "$pid" 2>/dev/null; do sleep 2; done
  wait "$pid" 2>/dev/null || true
  pid=""
  echo "$out/$name.png: $scene"
}

loop=$out/synth_loop
if [[ ! -f $loop/rgb.txt ]]; then
  "$orbis" synth "$loop" --frames 300 --extra 75 --width 320 --height 240 --fx 250 --noise 4 --seed 21 \
    --threads 2 >/dev/null
fi
shoot loop_closure "loops=1&view=top" "window.orbisScene.loopClosures >= 1" tum "$loop" --settings "$loop/settings.yaml"
corridor=$out/synth_corridor_black
if [[ ! -f $corridor/rgb.txt ]]; then
  "$orbis" synth "$corridor" --scene corridor --frames 300 --extra 75 --width 320 --height 240 --fx 250 --noise 4 \
    --seed 1 --black 100:30 --threads 2 >/dev/null
fi
shoot atlas_two_maps "view=top" "window.orbisScene.frames > 250 && window.orbisScene.maps >= 2" \
  tum "$corridor" --settings "$corridor/settings.yaml"
shoot atlas_merge "merges=1&view=top" "window.orbisScene.merges >= 1" tum "$corridor" --settings "$corridor/settings.yaml"
if [[ -d $data/tum_fr3_teddy_200 ]]; then
  shoot teddy_live "" "window.orbisScene.frames > 120 && window.orbisScene.images > 0" tum "$data/tum_fr3_teddy_200" --settings "$root/examples/settings/TUM3.yaml"
fi
if [[ -d $data/kitti_06_first51 ]]; then
  shoot kitti_live "" "window.orbisScene.frames > 30 && window.orbisScene.images > 0" kitti "$data/kitti_06_first51"
fi
