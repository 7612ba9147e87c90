#!/usr/bin/env bash
# The "must show" of issue 31, item 1: every bad input of `orbis calibrate` tried, with what orbis
# said and its exit code (a Markdown table; docs/notes/2026-11-26-fisheye.md holds the result).
# Fixtures are rendered with `orbis synth --pattern` (small, quick) and altered with ffmpeg (blur)
# and the shell; "no pattern" uses frames of the TUM teddy slice under ../shared/datasets.
#
# Usage: benchmarks/calibrate_bad_inputs.sh
#   ORBIS the binary (default build/release/orbis); WORK a scratch folder (default: a temporary one)
#   ORBIS_DATA the datasets (default ../shared/datasets)
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
B=${ORBIS:-$root/build/release/orbis}
D=${ORBIS_DATA:-$root/../shared/datasets}
W=${WORK:-$(mktemp -d)}
mkdir -p "$W" && cd "$W" || exit 1
n=0
P=chessboard:9x6:0.03

# row DESCRIPTION cmd...: what orbis said (its error lines) and the exit code; whether --out appeared.
row() {
  local desc=$1; shift
  n=$((n + 1))
  rm -f out.yaml
  local said rc
  said=$(timeout 600 "$@" 2>&1 >/dev/null); rc=$?
  said=$(echo "$said" | grep -vE "^calibrate: |^\s*$" | head -2 | sed -e 's/|/\\|/g' -e "s#$W/##g" -e "s#$D/##g" \
         | tr '\n' ' ' | cut -c1-600)
  [[ -z $said ]] && said="(nothing: calibrated)"
  local wrote="nothing written"
  [[ -f out.yaml ]] && wrote="wrote out.yaml"
  echo "| $n | $desc | $said | $rc | $wrote |"
}

# --- fixtures -------------------------------------------------------------------------------
synth() { [[ -d $1 ]] || "$B" synth "$1" --pattern "$P" --width 480 --height 360 --fx 380 --views "$2" --noise 1 --seed "${3:-3}" "${@:4}" >/dev/null; }
synth good 10
synth few 3
synth flat 10 6 --square-on
synth rig 10 4 --rig --baseline 0.08
synth small 10 5 --width 400 --height 300 --fx 320 --rig --baseline 0.08
rm -rf blurred && mkdir -p blurred
for f in good/images/*.png; do ffmpeg -loglevel error -y -i "$f" -vf gblur=sigma=3 "blurred/$(basename "$f")"; done
rm -rf nopattern && mkdir -p nopattern && for f in $(ls "$D"/tum_fr3_teddy_200/rgb/*.png | head -8); do ln -sf "$f" nopattern/; done
rm -rf unreadable && mkdir -p unreadable && echo "not an image" > unreadable/broken.png
rm -rf mixed && cp -r good/images mixed && echo "not an image" > mixed/view_005.png
rm -rf rig_short && cp -r rig rig_short && rm rig_short/right/view_009.png
rm -rf empty && mkdir -p empty

# --- the table ------------------------------------------------------------------------------
echo "| # | input | what orbis said | exit | files |"
echo "| --- | --- | --- | --- | --- |"
row "no image shows the pattern (TUM teddy frames)" "$B" calibrate images nopattern --pattern "$P" --out out.yaml
row "too few views (3)" "$B" calibrate images few/images --pattern "$P" --out out.yaml
row "a degenerate set (every board parallel to the image plane)" "$B" calibrate images flat/images --pattern "$P" --out out.yaml
row "blurred views only (Gaussian blur sigma 3 px)" "$B" calibrate images blurred --pattern "$P" --out out.yaml
row "wrong pattern size (8x6 for a 9x6 board)" "$B" calibrate images good/images --pattern chessboard:8x6:0.03 --out out.yaml
row "wrong pattern size (10x7, more corners than the board)" "$B" calibrate images good/images --pattern chessboard:10x7:0.03 --out out.yaml
row "a path that does not exist" "$B" calibrate images no/such/folder --pattern "$P" --out out.yaml
row "a folder without images" "$B" calibrate images empty --pattern "$P" --out out.yaml
row "an unreadable image only" "$B" calibrate images unreadable --pattern "$P" --out out.yaml
row "one unreadable image among 10 (the rest calibrate)" "$B" calibrate images mixed --pattern "$P" --out out.yaml
row "stereo: 10 left views, 9 right" "$B" calibrate images rig_short/left --right rig_short/right --pattern "$P" --out out.yaml
row "stereo: left 480x360, right 400x300" "$B" calibrate images rig/left --right small/right --pattern "$P" --out out.yaml
row "stereo: left and right swapped" "$B" calibrate images rig/right --right rig/left --pattern "$P" --out out.yaml
row "stereo: --right and --stereo together" "$B" calibrate images rig/left --right rig/right --stereo side-by-side --pattern "$P" --out out.yaml
row "wrong --pattern syntax (chessboard:9x6)" "$B" calibrate images good/images --pattern chessboard:9x6 --out out.yaml
row "wrong --pattern syntax (circles:4x11:0.02)" "$B" calibrate images good/images --pattern circles:4x11:0.02 --out out.yaml
row "wrong --model" "$B" calibrate images good/images --pattern "$P" --model omni --out out.yaml
row "a camera that does not exist (index 7)" "$B" calibrate camera 7 --pattern "$P" --out out.yaml --seconds 5
row "a camera that does not exist (/dev/video9)" "$B" calibrate camera /dev/video9 --pattern "$P" --out out.yaml --seconds 5
row "a video that does not exist" "$B" calibrate video no_such.mp4 --pattern "$P" --out out.yaml
row "good views, for comparison" "$B" calibrate images good/images --pattern "$P" --out out.yaml
