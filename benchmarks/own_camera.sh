#!/usr/bin/env bash
# The measurements of docs/notes/2026-11-26-own-camera.md: the same real frames run from a video,
# a folder and the dataset; a 1280x720 video played live with and without --resize; Ctrl-C; a
# missing camera.
#
# Usage: benchmarks/own_camera.sh [PART...]   PART: teddy, live, sigint, camera (default: all)
#   ORBIS     the binary (default build/release/orbis); needs ffmpeg (scripts/install-deps).
#   TEDDY     a TUM sequence (default ../shared/datasets/tum_fr3_teddy_200), TUM3 settings
#   CRF       H.264 quality of the encoded videos (default 23, ffmpeg's default)
#   ROUNDS    live runs of each kind (default 3)
#   KEEP      a folder to keep the work in (default: a temporary one, removed)
# Prints one line per run: tracked frames, Sim(3) ATE (teddy) or dropped frames and latency
# (live), from each run's report.json.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
orbis=${ORBIS:-$root/build/release/orbis}
teddy=${TEDDY:-$root/../shared/datasets/tum_fr3_teddy_200}
crf=${CRF:-23}
rounds=${ROUNDS:-3}
parts=${*:-teddy live sigint camera}
if [[ -n "${KEEP:-}" ]]; then work=$KEEP; mkdir -p "$work"; else work=$(mktemp -d); trap 'rm -rf "$work"' EXIT; fi
settings=$root/examples/settings/TUM3.yaml

summary() {  # report.json -> one line
  python3 - "$1" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
ate = r["ate"]
s = r["source"]
lat = r["latency_ms"]
print(f'{r["frames_tracked"]:4d}/{r["frames"]:<4d} tracked  kf {r["keyframes"]:3d}  '
      + (f'ATE {1000 * ate["rmse"]:6.1f} mm over {ate["matched"]:3d} ({ate["alignment"]})  ' if ate else 'ATE -  ')
      + f'dropped {s["dropped_frames"]:4d}  latency median {lat["median"]:6.1f} p95 {lat["p95"]:6.1f} ms  '
      + f'size {s["input_size"]}{" -> " + str(s["resized_to"]) if s["resized_to"] else ""}  {r["seconds"]:.1f} s'
      + ('  INTERRUPTED' if r["interrupted"] else ''))
PY
}

# Frames in a list's order as 0000.png ... for ffmpeg's image2 reader.
numbered() {  # list_file image_root out_dir
  mkdir -p "$3"
  awk '!/^#/ && NF >= 2 {print $2}' "$1" | nl -v0 -nrz -w4 | while read -r i f; do ln -sf "$2/$f" "$3/$i.png"; done
}

if [[ " $parts " == *" teddy "* ]]; then
  echo "== teddy: video (H.264 crf $crf, 30 fps) vs image folder vs dataset, monocular, --deterministic"
  numbered "$teddy/rgb.txt" "$teddy" "$work/teddy_frames"
  ffmpeg -y -loglevel error -framerate 30 -i "$work/teddy_frames/%04d.png" -c:v libx264 -crf "$crf" -pix_fmt yuv420p \
    "$work/teddy.mp4"
  echo "video: $(du -k "$work/teddy.mp4" | cut -f1) kB, frames: $(du -kL "$work/teddy_frames" | tail -1 | cut -f1) kB of PNG"
  common=(--settings "$settings" --deterministic)
  "$orbis" run tum "$teddy" --sensor mono "${common[@]}" --out "$work/t_dataset" >/dev/null
  "$orbis" run images "$teddy/rgb" --times "$teddy/rgb.txt" --groundtruth "$teddy/groundtruth.txt" "${common[@]}" \
    --out "$work/t_images" >/dev/null
  "$orbis" run video "$work/teddy.mp4" --times "$teddy/rgb.txt" --groundtruth "$teddy/groundtruth.txt" "${common[@]}" \
    --out "$work/t_video" >/dev/null
  for k in dataset images video; do printf '%-8s ' "$k"; summary "$work/t_$k/report.json"; done
  cmp -s "$work/t_dataset/trajectory.txt" "$work/t_images/trajectory.txt" && echo "images = dataset: trajectories byte-identical"
  echo "-- the same threaded (default mode), ${rounds} runs each"
  for i in $(seq "$rounds"); do
    for k in images video; do
      src=$teddy/rgb; [[ $k == video ]] && src=$work/teddy.mp4
      "$orbis" run "$k" "$src" --times "$teddy/rgb.txt" --groundtruth "$teddy/groundtruth.txt" --settings "$settings" \
        --out "$work/t_${k}_$i" >/dev/null
      printf '%-8s ' "$k#$i"; summary "$work/t_${k}_$i/report.json"
    done
  done
fi

if [[ " $parts " == *" live "* ]]; then
  echo "== a 1280x720 hand-held-like video (rendered: noise 2, motion blur), 30 fps, played --realtime"
  if [[ ! -f "$work/hd.mp4" ]]; then
    "$orbis" synth "$work/hd" --layout tum --frames 300 --width 1280 --height 720 --fx 900 --noise 2 --blur 2 \
      --supersample 1 --threads 2 --seed 5 >/dev/null
    numbered "$work/hd/rgb.txt" "$work/hd" "$work/hd_frames"
    ffmpeg -y -loglevel error -framerate 30 -i "$work/hd_frames/%04d.png" -c:v libx264 -crf "$crf" -pix_fmt yuv420p \
      "$work/hd.mp4"
  fi
  for i in $(seq "$rounds"); do
    for resize in none 640; do
      extra=(); [[ $resize != none ]] && extra=(--resize "$resize")
      "$orbis" run video "$work/hd.mp4" --realtime --times "$work/hd/rgb.txt" --groundtruth "$work/hd/groundtruth.txt" \
        --settings "$work/hd/settings_mono.yaml" "${extra[@]}" --out "$work/hd_${resize}_$i" >/dev/null
      printf '%-12s ' "resize $resize"; summary "$work/hd_${resize}_$i/report.json"
    done
  done
fi

if [[ " $parts " == *" sigint "* ]]; then
  echo "== SIGINT 5 s into a --realtime run of the teddy video"
  [[ -f "$work/teddy.mp4" ]] || { echo "run the teddy part first"; exit 1; }
  "$orbis" run video "$work/teddy.mp4" --realtime --times "$teddy/rgb.txt" --settings "$settings" \
    --out "$work/sigint" --save-map "$work/sigint/teddy.map" >/dev/null 2>"$work/sigint.err" &
  pid=$!
  sleep 5
  kill -INT "$pid"
  set +e; wait "$pid"; status=$?; set -e
  echo "exit status $status; $(tail -1 "$work/sigint.err")"
  ls "$work/sigint"
  summary "$work/sigint/report.json"
fi

if [[ " $parts " == *" camera "* ]]; then
  echo "== a camera that does not exist"
  start=$(date +%s.%N)
  set +e; "$orbis" run camera 7 --settings "$settings" --out "$work/cam" 2>"$work/cam.err"; status=$?; set -e
  end=$(date +%s.%N)
  echo "exit status $status after $(python3 -c "print(f'{$end - $start:.2f}')") s: $(cat "$work/cam.err")"
fi
