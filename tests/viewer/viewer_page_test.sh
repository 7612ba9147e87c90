#!/usr/bin/env bash
# The live viewer as a person uses it: `orbis run --viewer` on a rendered loop (closed at frame
# ~119, then 120 frames more over known ground), the page loaded in headless Chromium while SLAM
# runs — its screenshot is taken once the page has seen the loop closure (page_probe.py) — and
# after it has finished; the scene the page holds (window.orbisScene,
# mirrored in #scene-state) must match the run's report.json, and the camera image must have
# been drawn. Screenshots:
# WORK_DIR/viewer_live.png and WORK_DIR/viewer_final.png.
#
# Usage: viewer_page_test.sh ORBIS_BINARY WORK_DIR
# Exits 77 (ctest: skipped) when chromium is not installed.
set -euo pipefail
orbis=$1
work=$2
chromium=$(command -v chromium || command -v chromium-browser || true)
if [[ -z $chromium ]]; then
  echo "viewer_page_test: chromium not found, skipped"
  exit 77
fi
mkdir -p "$work"
rm -rf "$work/out" "$work"/viewer_*.png
if [[ ! -f $work/synth/rgb.txt ]]; then
  "$orbis" synth "$work/synth" --layout tum --frames 120 --extra 120 --width 320 --height 240 --fx 250 --seed 3 \
    --threads 2 >/dev/null
fi

# A free port: orbis refuses a busy one at once.
pid=""
for port in 18751 18752 18753 18754 18755; do
  "$orbis" run tum "$work/synth" --settings "$work/synth/settings.yaml" --out "$work/out" \
    --viewer "$port" --viewer-wait >"$work/run.log" 2>&1 &
  pid=$!
  sleep 0.5
  if kill -0 "$pid" 2>/dev/null; then break; fi
  pid=""
done
[[ -n $pid ]] || { echo "no free port"; cat "$work/run.log"; exit 1; }
# TERM, not INT: a script's background job starts with SIGINT ignored until orbis installs its
# Ctrl-C handler, so an early exit would leave it serving.
trap 'kill -TERM $pid 2>/dev/null || true; wait $pid 2>/dev/null || true' EXIT
url="http://127.0.0.1:$port/"

# While SLAM runs: the page closes its stream once the map holding a loop closure has arrived
# (?loops=1), which freezes it at that moment; the probe waits for it over the DevTools protocol
# and takes the screenshot. The page must have seen the closure live, during the run.
probe=$(dirname "$0")/page_probe.py
live=$(python3 "$probe" "$url?loops=1&view=top" --until "window.orbisScene.loopClosures >= 1" \
  --screenshot "$work/viewer_live.png" --timeout 240 --chromium "$chromium") || { echo "no loop closure on the page: $live"; exit 1; }
echo "page at the loop closure: $live"
python3 -c "import json,sys; s=json.loads(sys.argv[1]); assert s['live'] is True and s['images'] >= 1, s" "$live"
for _ in $(seq 600); do
  grep -q "serving the finished run" "$work/run.log" && break
  kill -0 "$pid" 2>/dev/null || { echo "orbis run ended early:"; cat "$work/run.log"; exit 1; }
  sleep 0.5
done
grep -q "serving the finished run" "$work/run.log" || { echo "the run did not finish"; exit 1; }

# After the run: the page's scene against the report, once the final map and image are shown.
scene=$(python3 "$probe" "$url" --until "window.orbisScene.live === false && window.orbisScene.images >= 1" \
  --screenshot "$work/viewer_final.png" --timeout 60 --chromium "$chromium") || { echo "final page: $scene"; exit 1; }
echo "page: $scene"
python3 - "$scene" "$work/out/report.json" <<'PY'
import json, sys
scene = json.loads(sys.argv[1].replace("&quot;", '"'))
report = json.load(open(sys.argv[2]))
print("report: keyframes %d, map points %d, frames %d" % (report["keyframes"], report["map_points"], report["frames"]))
assert scene["keyframes"] > 0 and scene["points"] > 0 and scene["frames"] > 0, scene
assert scene["keyframes"] == report["keyframes"], "keyframes differ"
assert scene["points"] == report["map_points"], "map points differ"
assert scene["frames"] == report["frames"], "frames differ"
assert scene["live"] is False, "the page should show the finished run"
assert scene["loopClosures"] >= 1, "the rendered loop should have closed"
assert scene["images"] >= 1, "the page should show the camera image"
PY
for shot in viewer_live viewer_final; do
  [[ -s $work/$shot.png ]] || { echo "no screenshot $shot.png"; exit 1; }
done
echo "screenshots: $work/viewer_live.png $work/viewer_final.png"
