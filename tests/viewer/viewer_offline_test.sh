#!/usr/bin/env bash
# The viewer with the network cable out: `orbis run --viewer` and headless Chromium run inside a
# network namespace that has only a loopback interface (unshare -n), so nothing can leave the
# machine; page_probe.py logs the page's requests (DevTools) and Chromium all of its own
# (--log-net-log). The page must still show the whole finished run (keyframes, points, the camera
# image: window.orbisScene), every request the page made must be to the viewer on 127.0.0.1, and
# the net log must hold them (the browser's own service requests are listed apart).
#
# Usage: viewer_offline_test.sh ORBIS_BINARY WORK_DIR
# Exits 77 (ctest: skipped) when chromium is not installed or no network namespace can be made
# (unprivileged, user namespaces off).
set -euo pipefail
orbis=$1
work=$2
chromium=$(command -v chromium || command -v chromium-browser || true)
if [[ -z $chromium ]]; then
  echo "viewer_offline_test: chromium not found, skipped"
  exit 77
fi
# As root a plain network namespace; otherwise one inside a user namespace, where allowed.
netns=()
for candidate in "unshare -n" "unshare -r -n"; do
  if $candidate true 2>/dev/null; then
    read -r -a netns <<<"$candidate"
    break
  fi
done
if ((${#netns[@]} == 0)); then
  echo "viewer_offline_test: cannot create a network namespace (unshare -n), skipped"
  exit 77
fi
mkdir -p "$work"
rm -rf "$work/out" "$work/netlog.json" "$work/requests.txt" "$work/run.log" "$work/scene.json" "$work/interfaces.txt"
if [[ ! -f $work/synth/rgb.txt ]]; then  # short: a map, a camera image; no loop needed here
  "$orbis" synth "$work/synth" --layout tum --frames 60 --width 320 --height 240 --fx 250 --seed 5 \
    --threads 2 >/dev/null
fi

# Everything below the namespace line sees only `lo`; the port is fixed (the namespace is empty).
probe=$(cd "$(dirname "$0")" && pwd)/page_probe.py
"${netns[@]}" bash -s "$orbis" "$chromium" "$work" "$probe" <<'INSIDE'
set -euo pipefail
orbis=$1 chromium=$2 work=$3 probe=$4 port=18761
ip link set lo up 2>/dev/null || true  # up already in some kernels; without `ip`, loopback may be down
ip -o link >"$work/interfaces.txt" 2>/dev/null || : >"$work/interfaces.txt"  # no `ip`: not listed
"$orbis" run tum "$work/synth" --settings "$work/synth/settings.yaml" --out "$work/out" \
  --viewer "$port" --viewer-wait >"$work/run.log" 2>&1 &
pid=$!
trap 'kill -TERM $pid 2>/dev/null || true; wait $pid 2>/dev/null || true' EXIT
for _ in $(seq 100); do
  (exec 3<>/dev/tcp/127.0.0.1/$port) 2>/dev/null && break
  kill -0 "$pid" 2>/dev/null || { echo "orbis run ended early:"; cat "$work/run.log"; exit 1; }
  sleep 0.1
done
# The page loads while SLAM runs and is read once it shows the finished run with its image.
python3 "$probe" "http://127.0.0.1:$port/" \
  --until "window.orbisScene.live === false && window.orbisScene.images >= 1" --timeout 120 \
  --chromium "$chromium" --chromium-arg=--log-net-log="$work/netlog.json" --requests "$work/requests.txt" \
  --screenshot "$work/offline.png" >"$work/scene.json"
INSIDE

scene=$(cat "$work/scene.json")
echo "interfaces in the namespace: $(awk '{print $2}' "$work/interfaces.txt" | tr '\n' ' ')"
echo "page: $scene"
python3 - "$scene" "$work/out/report.json" "$work/netlog.json" "$work/interfaces.txt" "$work/requests.txt" <<'PY'
import json, re, sys
scene = json.loads(sys.argv[1].replace("&quot;", '"'))
report = json.load(open(sys.argv[2]))
assert scene["keyframes"] == report["keyframes"] and scene["points"] == report["map_points"], (scene, report)
assert scene["images"] >= 1, "the camera image did not reach the page"
interfaces = {l.split()[1].rstrip(":") for l in open(sys.argv[4]) if l.split()[1:]}
assert interfaces <= {"lo"}, "the namespace has more than loopback: %s" % interfaces
# What the page requested (DevTools, its own target: documents, scripts, the event stream) must all
# be the viewer's; data: URLs are decoded in place. The browser's net log also holds the browser's
# own service requests (component updates, clock, spell-check dictionary; no flag turns them all
# off): listed, not the page's, and they could not leave the namespace either.
local = re.compile(r"http://127\.0\.0\.1:\d+/")
page = sorted({u for u in open(sys.argv[5]).read().split() if not u.startswith("data:")})
print("page requests: " + " ".join(page))
foreign = [u for u in page if not local.match(u)]
assert not foreign, "the page requested off the machine: %s" % foreign
paths = {local.sub("/", u) for u in page}
for needed in ("/", "/three.min.js", "/OrbitControls.js", "/scene_store.js", "/panel.js", "/viewer.js", "/events"):
    assert needed in paths, "no request for %s" % needed
# The net log is JSON that a killed browser may leave unterminated: read its URLs textually.
logged = set(re.findall(r'"url":"([^"]+)"', open(sys.argv[3], errors="replace").read()))
assert set(page) <= logged, "the net log misses requests the page made: %s" % (set(page) - logged)
service = sorted(re.sub(r"\?.*", "?…", u) for u in logged - set(page) if not u.startswith("data:"))
print("browser's own requests (not the page's; no network here): " + (" ".join(service) or "none"))
print("offline: the page made %d requests, all to the viewer on 127.0.0.1" % len(page))
PY
