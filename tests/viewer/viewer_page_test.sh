#!/usr/bin/env bash
# The live viewer as a person uses it: `orbis run --viewer` on a rendered loop (closed at frame
# ~119, then 120 frames more over known ground) with a page in headless Chromium open from the
# start (page_probe.py; its screenshot is taken once it shows the loop closure, live) to the end,
# and a second page that joins late. The scene both hold at the end (window.orbisScene, mirrored
# in #scene-state) must match the run's report.json — the first page built it from changes, the
# late one from the whole map it got on joining — and the camera image must have been drawn.
# Screenshots: WORK_DIR/viewer_live.png and WORK_DIR/viewer_final.png.
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

# The first page is open before SLAM starts (page_probe --ready-file: the browser starts, then
# loads the page as soon as orbis serves it), so it sees the whole map once, then only changes
# (map_delta.hpp). Its screenshot is taken once it shows the loop closure, live; it stays to
# the end. The run is paced at the sequence's frame rate (--realtime), as a camera feeds it: the
# viewer's threads run at the lowest priority and, with frames fed as fast as tracking goes on a
# machine the other tests keep busy, may get no time until SLAM has finished. A free port: orbis
# refuses a busy one at once.
probe=$(dirname "$0")/page_probe.py
pid="" first=""
for port in 18751 18752 18753 18754 18755; do
  rm -f "$work/ready"
  python3 "$probe" "http://127.0.0.1:$port/?view=top" --ready-file "$work/ready" \
    --until "window.orbisScene.loopClosures >= 1" --screenshot "$work/viewer_live.png" \
    --then "window.orbisScene.live === false && window.orbisScene.images >= 1" \
    --timeout 240 --chromium "$chromium" >"$work/first_page.txt" 2>&1 &
  first=$!
  for _ in $(seq 300); do [[ -e $work/ready ]] && break; sleep 0.1; done
  "$orbis" run tum "$work/synth" --settings "$work/synth/settings.yaml" --out "$work/out" \
    --realtime --viewer "$port" --viewer-wait >"$work/run.log" 2>&1 &
  pid=$!
  sleep 0.5
  if kill -0 "$pid" 2>/dev/null; then break; fi
  kill -TERM "$first" 2>/dev/null || true
  wait "$first" 2>/dev/null || true
  pid="" first=""
done
[[ -n $pid ]] || { echo "no free port"; cat "$work/run.log"; exit 1; }
# TERM, not INT: a script's background job starts with SIGINT ignored until orbis installs its
# Ctrl-C handler, so an early exit would leave it serving.
trap 'kill -TERM $pid $first 2>/dev/null || true; wait $pid $first 2>/dev/null || true' EXIT
url="http://127.0.0.1:$port/"

# A page that joins late (once the first has seen the loop closure: during the run, or after it
# on a fast machine) gets the whole map at once, then the changes.
for _ in $(seq 2400); do
  [[ -s $work/first_page.txt ]] && break
  kill -0 "$first" 2>/dev/null || break
  sleep 0.1
done
late=$(python3 "$probe" "$url" --until "window.orbisScene.live === false && window.orbisScene.images >= 1" \
  --screenshot "$work/viewer_final.png" --timeout 240 --chromium "$chromium") || { echo "late page: $late"; exit 1; }
wait "$first" || { echo "first page:"; cat "$work/first_page.txt"; exit 1; }
live=$(sed -n 1p "$work/first_page.txt")
whole=$(sed -n 2p "$work/first_page.txt")
echo "first page at the loop closure: $live"
echo "first page at the end: $whole"
echo "page that joined late: $late"
python3 -c "import json,sys; s=json.loads(sys.argv[1]); assert s['live'] is True and s['images'] >= 1, s" "$live"
python3 -c "import json,sys; s=json.loads(sys.argv[1]); assert s['mapDeltas'] >= 1, s" "$whole"
for _ in $(seq 600); do
  grep -q "serving the finished run" "$work/run.log" && break
  kill -0 "$pid" 2>/dev/null || { echo "orbis run ended early:"; cat "$work/run.log"; exit 1; }
  sleep 0.5
done
grep -q "serving the finished run" "$work/run.log" || { echo "the run did not finish"; exit 1; }

python3 - "$work/out/report.json" "$whole" "$late" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
print("report: keyframes %d, map points %d, frames %d" % (report["keyframes"], report["map_points"], report["frames"]))
for name, text in (("first page", sys.argv[2]), ("page that joined late", sys.argv[3])):
    scene = json.loads(text.replace("&quot;", '"'))
    assert scene["keyframes"] > 0 and scene["points"] > 0 and scene["frames"] > 0, (name, scene)
    assert scene["keyframes"] == report["keyframes"], "%s: keyframes differ" % name
    assert scene["points"] == report["map_points"], "%s: map points differ" % name
    assert scene["frames"] == report["frames"], "%s: frames differ" % name
    assert scene["live"] is False, "%s: the page should show the finished run" % name
    assert scene["loopClosures"] >= 1, "%s: the rendered loop should have closed" % name
    assert scene["images"] >= 1, "%s: the page should show the camera image" % name
    assert scene["fullMaps"] >= 1, "%s: a page that joins gets the whole map" % name
PY
for shot in viewer_live viewer_final; do
  [[ -s $work/$shot.png ]] || { echo "no screenshot $shot.png"; exit 1; }
done
echo "screenshots: $work/viewer_live.png $work/viewer_final.png"
