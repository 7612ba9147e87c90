#!/usr/bin/env bash
# The live viewer as a person uses it: `orbis run --viewer` on a rendered loop (closed at frame
# ~119, then 120 frames more over known ground), the page loaded in headless Chromium while SLAM
# runs — its screenshot is taken once the page has seen the loop closure, or at the latest when
# the run ends — and after it has finished; the scene the page holds (window.orbisScene,
# mirrored in #scene-state) must match the run's report.json. Screenshots:
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

browse() {  # browse URL ARGS...: headless Chromium, bounded in time, its chatter dropped
  local url=$1
  shift
  timeout 90 "$chromium" --headless --disable-gpu --no-sandbox --hide-scrollbars --window-size=1400,800 \
    --user-data-dir="$work/chromium-profile" "$@" "$url" 2>/dev/null
}

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

# While SLAM runs: the page closes its stream (and Chromium takes the picture) once a loop closure
# has arrived, or when the run is over if the page connected that late.
browse "$url?loops=1" --screenshot="$work/viewer_live.png" >/dev/null
for _ in $(seq 600); do
  grep -q "serving the finished run" "$work/run.log" && break
  kill -0 "$pid" 2>/dev/null || { echo "orbis run ended early:"; cat "$work/run.log"; exit 1; }
  sleep 0.5
done
grep -q "serving the finished run" "$work/run.log" || { echo "the run did not finish"; exit 1; }

# After the run: the page's scene against the report.
# The DOM is dumped once the page's scripts have had their (virtual) time; on a loaded machine the
# scene may not have arrived yet, so ask again a few times before judging.
scene=""
for attempt in 1 2 3 4 5; do
  scene=$(browse "$url" --virtual-time-budget=$((2000 * attempt)) --dump-dom |
    sed -n 's/.*<pre id="scene-state">\([^<]*\)<.*/\1/p')
  [[ -n $scene && $scene == *keyframes* ]] && break
  sleep 1
done
browse "$url" --screenshot="$work/viewer_final.png" >/dev/null
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
PY
for shot in viewer_live viewer_final; do
  [[ -s $work/$shot.png ]] || { echo "no screenshot $shot.png"; exit 1; }
done
echo "screenshots: $work/viewer_live.png $work/viewer_final.png"
