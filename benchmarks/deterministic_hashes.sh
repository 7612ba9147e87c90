#!/usr/bin/env bash
# Deterministic trajectory hashes of the shared slices: a change that should not move any
# trajectory (a speed-up) must leave every line of this output unchanged.
#   benchmarks/deterministic_hashes.sh [ORBIS_BINARY]
# Environment: ORBIS_DATA (default ../shared/datasets from the repository), WORK (scratch
# folder, default /tmp/orbis_hashes). Prints "label sha256(trajectory.txt) sha256(keyframes.txt)
# frames-tracked keyframes".
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
orbis="${1:-$here/build/release/orbis}"
data="${ORBIS_DATA:-$here/../shared/datasets}"
work="${WORK:-/tmp/orbis_hashes}"
[ -x "$orbis" ] || { echo "deterministic_hashes: $orbis is not an executable orbis" >&2; exit 1; }
mkdir -p "$work"
run() {  # label kind folder [extra args...]
  local label="$1" kind="$2" folder="$3"
  shift 3
  if [ ! -d "$data/$folder" ]; then echo "$label skipped ($data/$folder not found)"; return; fi
  local out="$work/$label"
  rm -rf "$out"
  "$orbis" run "$kind" "$data/$folder" --deterministic --out "$out" --json "$@" > "$out.json"
  local traj kfs
  traj=$(sha256sum "$out/trajectory.txt" | cut -c1-16)
  kfs=$(sha256sum "$out/keyframes.txt" | cut -c1-16)
  echo "$label $traj $kfs $(wc -l < "$out/trajectory.txt") $(wc -l < "$out/keyframes.txt")"
}
run teddy-rgbd tum tum_fr3_teddy_200
run teddy-mono tum tum_fr3_teddy_200 --sensor mono
run kitti06-stereo kitti kitti_06_first51
run kitti06-mono kitti kitti_06_first51 --sensor mono
run kitti0102-stereo kitti kitti_0102_first51
run euroc-stereo euroc euroc_V1_01_easy_95
