#!/usr/bin/env bash
# Deterministic trajectory hashes of the shared real slices (issue 32: the atlas must leave runs
# where nothing is lost byte-identical). Prints one line per slice: name, frames tracked, maps,
# sha256 of trajectory.txt. Run it with the build before and after a change and diff the output.
#   benchmarks/atlas_hashes.sh [ORBIS_BINARY]   (default build/release/orbis)
# Environment: ORBIS_DATA (default ../shared/datasets), WORK (default /tmp/orbis_atlas_hashes).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
orbis="${1:-$root/build/release/orbis}"
data="${ORBIS_DATA:-$root/../shared/datasets}"
work="${WORK:-/tmp/orbis_atlas_hashes}"
settings="$root/examples/settings"
mkdir -p "$work"
k06="$data/kitti_06_first51"
k0102="$data/kitti_0102_first51"
slices=(
  "teddy_rgbd|tum $data/tum_fr3_teddy_200 --settings $settings/TUM3.yaml"
  "teddy_mono|tum $data/tum_fr3_teddy_200 --settings $settings/TUM3.yaml --sensor mono"
  "kitti06_stereo|kitti $k06 --settings $settings/KITTI04-12.yaml"
  "kitti06_mono|kitti $k06 --settings $settings/KITTI04-12.yaml --sensor mono"
  "kitti0102_stereo|kitti $k0102 --settings $settings/KITTI00-02.yaml"
  "euroc_stereo|euroc $data/euroc_V1_01_easy_95 --settings $settings/EuRoC.yaml"
)
for entry in "${slices[@]}"; do
  name="${entry%%|*}"
  read -r -a args <<<"${entry#*|}"
  out="$work/$name"
  rm -rf "$out"
  "$orbis" run "${args[@]}" --deterministic --out "$out" >/dev/null 2>"$work/$name.stderr" || true
  if [[ -f "$out/trajectory.txt" ]]; then
    hash="$(sha256sum "$out/trajectory.txt" | cut -c1-16)"
    tracked="$(python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(r.get('frames_tracked'), r.get('frames'))" "$out/report.json")"
  else
    hash="(no trajectory)"
    tracked="-"
  fi
  echo "$name tracked/frames=$tracked sha256=$hash"
done
