#!/usr/bin/env bash
# Does monocular SLAM keep its scale? One row per rendered seed, run in --deterministic mode
# with --no-loop (loop closing would hide a collapse behind its Sim(3) correction).
# Why: three seeds (benchmarks/mono_loops.sh) are too few to see how often the map loses its
# scale. On the standard room, 3 of 8 seeds (41-48) did, while 41-43 alone looked healthy.
# Columns:
#   init     the frame the map initialised at, and the model it came from (homography or
#            fundamental, with the parallax of the 51st most parallactic point)
#   tracked  frames tracked after initialisation / frames after initialisation
#   ATE      Sim(3)-aligned ATE over all frames (mm)
#   scale    the estimate's size over 60-frame stretches starting every 100 frames, against the
#            first 60 frames (relative_size in mono_scenes.sh, as mono_loops.sh's scale column): 1
#            keeps the scale; a map that lost it reads well under 1 and stays there
#
# Usage: benchmarks/mono_scale_seeds.sh [SEED...]      (default seeds 41 to 48)
#   SCENE=room|corridor (default room; the same renders as mono_loops.sh), ORBIS the binary
#   (default build/release/orbis), WORK a scratch folder (renders are kept there and reused;
#   default: a temporary one), SIZE="W H FX" overrides 320 240 250, JOBS parallel runs (default 2).
set -euo pipefail
source "$(dirname "$0")/mono_scenes.sh" room
seeds=("$@")
((${#seeds[@]})) || seeds=(41 42 43 44 45 46 47 48)

one_seed() {  # SEED: renders if needed, runs, prints the row
  local seed=$1 seq out gt rows starts=() sizes=() k
  seq=$(render_mono_scene "$seed" 1)
  gt=$seq/groundtruth.txt
  out=$work/run_${seed}_noloop
  "$orbis" run tum "$seq" --settings "$seq/settings_mono.yaml" --sensor mono --deterministic --no-loop \
    --stats --out "$out" >"$out.log" 2>&1
  rows=$(grep -vc '^#' "$out/trajectory.txt" || true)
  for ((start = 100; start < rows - 60; start += 100)); do starts+=("$start"); done
  if ((${#starts[@]})); then
    mapfile -t sizes < <(relative_size "$gt" "$out/trajectory.txt" "${starts[@]}")
    for k in "${!starts[@]}"; do sizes[k]="${starts[k]}:${sizes[k]}"; done
  fi
  python3 - "$seed" "$out" "${sizes[@]}" <<'PY'
import json, sys
seed, out, sizes = sys.argv[1], sys.argv[2], sys.argv[3:]
report = json.load(open(f"{out}/report.json"))
init = report["initialisation"]["frame"]
if init is None:  # never initialised: say what it waited on
    waits = ", ".join(f"{k} {v}" for k, v in sorted(report["initialisation"]["waits"].items()))
    sys.exit(print(f"{seed:<5} never initialised (waited on: {waits})"))
model = ""
for line in open(f"{out}/stats.jsonl"):
    row = json.loads(line)
    if row.get("kind") == "frame" and row.get("frame") == init and "initialisation_homography" in row:
        kind = "H" if row["initialisation_homography"] else "F"
        model = f'{kind} {row["initialisation_parallax_deg"]:.2f}°'
after = report["frames"] - init
print(f'{seed:<5} {init:<4} {model:<8} {report["frames_tracked"] - 1}/{after:<6} '
      f'{report["ate"]["rmse"] * 1000:8.1f}   {" ".join(sizes) or "-"}')
PY
}

printf '%-5s %-13s %-10s %8s   %s\n' seed "init (model)" tracked "ATE mm" "scale against the first 60 frames"
export -f one_seed render_mono_scene stretch_scale relative_size
export orbis work width height fx scene frames extra
printf '%s\n' "${seeds[@]}" | xargs -P "${JOBS:-2}" -I{} bash -c 'one_seed {}' | sort -n
