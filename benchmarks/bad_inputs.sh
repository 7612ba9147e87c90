#!/usr/bin/env bash
# The "must show" table of issue 19: bad or unusual inputs handed to orbis, each built here from
# ../shared/datasets (read-only; copies and symlinks under WORK), what orbis said, its exit code,
# and whether what was already on disk survived.
#
# Usage: benchmarks/bad_inputs.sh            (prints a Markdown table; takes a few minutes)
#   ORBIS the binary (default build/release/orbis); WORK a scratch folder (default: a temporary one)
#   ORBIS_DATA the datasets (default ../shared/datasets)
# Every `orbis run` writes into an output folder that already holds a file from "an earlier run"
# (kept.txt): the last column says whether it is still there, unchanged, afterwards ("kept"), and
# which outputs the run wrote. For --save-map and the vocabulary, a file already at the target
# path is checked the same way. "said" is the first three warning or error lines.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
B=${ORBIS:-$root/build/release/orbis}
D=${ORBIS_DATA:-$root/../shared/datasets}
W=${WORK:-$(mktemp -d)}
TD=$D/tum_fr3_teddy_200 E=$D/euroc_V1_01_easy_95 K=$D/kitti_06_first51 R=$D/reference
mkdir -p "$W" && cd "$W" || exit 1
n=0

# row DESCRIPTION OUT cmd...   OUT: the output folder the command writes to, or "-" for none.
row() {
  local desc=$1 out=$2; shift 2
  n=$((n + 1))
  if [[ $out != - ]]; then rm -rf "$out"; mkdir -p "$out"; echo "earlier run" > "$out/kept.txt"; fi
  local said rc
  said=$(timeout 300 "$@" 2>&1 >/dev/null); rc=$?
  said=$(echo "$said" | grep -E "error|warning|unknown|libpng" | head -3 | sed -e 's/|/\\|/g' -e "s#$W/##g" -e "s#$D/##g" \
         | tr '\n' ' ' | cut -c1-360)
  [[ -z $said ]] && said="(nothing: ran)"
  local disk="-"
  if [[ $out != - ]]; then
    if [[ "$(cat "$out/kept.txt" 2>/dev/null)" == "earlier run" ]]; then disk=kept; else disk=LOST; fi
    local wrote
    wrote=$(cd "$out" && ls | grep -v '^kept.txt$' | tr '\n' ' ')
    [[ -n $wrote ]] && disk="$disk; wrote $wrote"
  fi
  echo "| $n | $desc | $said | $rc | $disk |"
}

# --- fixtures -------------------------------------------------------------------------------
mktum() {  # mktum DIR: teddy with its lists copied and its image folders linked
  rm -rf "$1"; mkdir -p "$1"; cp "$TD"/*.txt "$1/"; ln -s "$TD/rgb" "$1/rgb"; ln -s "$TD/depth" "$1/depth"; }
mktum tum_nodepth; grep '^#' "$TD/depth.txt" > tum_nodepth/depth.txt
mktum tum_nodepthlist; rm tum_nodepthlist/depth.txt
mktum tum_nodepthdir; rm tum_nodepthdir/depth
mktum tum_shuffled; { grep '^#' "$TD/rgb.txt"; grep -v '^#' "$TD/rgb.txt" | shuf --random-source=<(yes); } > tum_shuffled/rgb.txt
mktum tum_rep; grep -v '^#' "$TD/rgb.txt" | sed -n 100,102p >> tum_rep/rgb.txt; grep -v '^#' "$TD/groundtruth.txt" | sed -n 500p >> tum_rep/groundtruth.txt
mktum tum_empty; grep '^#' "$TD/rgb.txt" > tum_empty/rgb.txt
mktum tum_norgb; rm tum_norgb/rgb; mkdir tum_norgb/rgb
mktum tum_8bit
paste -d' ' <(grep -v '^#' "$TD/depth.txt" | cut -d' ' -f1) <(grep -v '^#' "$TD/rgb.txt" | cut -d' ' -f2) > tum_8bit/depth.txt
mktum tum_crlf; sed 's/$/\r/' "$TD/rgb.txt" > tum_crlf/rgb.txt
mktum tum_nan; sed '10s/^\([0-9.]*\) /nan /' "$TD/rgb.txt" > tum_nan/rgb.txt
mke() {  # mke DIR: the EuRoC slice with data.csv and sensor.yaml copied, images linked
  rm -rf "$1"; mkdir -p "$1/mav0/state_groundtruth_estimate0"
  for c in cam0 cam1; do mkdir -p "$1/mav0/$c"; ln -s "$E/mav0/$c/data" "$1/mav0/$c/data"; cp "$E/mav0/$c/data.csv" "$E/mav0/$c/sensor.yaml" "$1/mav0/$c/"; done
  cp "$E/mav0/state_groundtruth_estimate0/data.csv" "$1/mav0/state_groundtruth_estimate0/"; }
mke asl; for c in cam0 cam1; do tail -n +2 "$E/mav0/$c/sensor.yaml" > asl/mav0/$c/sensor.yaml; done
mke e_badpng; for c in cam0 cam1; do rm "e_badpng/mav0/$c/data"; mkdir "e_badpng/mav0/$c/data"; for f in "$E/mav0/$c/data/"*.png; do ln -s "$f" "e_badpng/mav0/$c/data/"; done; done
f() { grep -v '^#' "$E/mav0/$1/data.csv" | sed -n "$2p" | cut -d, -f2 | tr -d '\r'; }
rm "e_badpng/mav0/cam0/data/$(f cam0 11)" "e_badpng/mav0/cam1/data/$(f cam1 21)"
p=e_badpng/mav0/cam0/data/$(f cam0 31); rm "$p"; head -c 3000 "$E/mav0/cam0/data/$(f cam0 31)" > "$p"
p=e_badpng/mav0/cam1/data/$(f cam1 41); rm "$p"; : > "$p"
mke eo; { head -1 "$E/mav0/cam0/data.csv"; tail -n +2 "$E/mav0/cam0/data.csv" | tac; } > eo/mav0/cam0/data.csv
mke ef; sed '5s/^1403715\([0-9]*\),/1.4e18,/' "$E/mav0/cam0/data.csv" > ef/mav0/cam0/data.csv
mke et; awk -F, 'NR>1 {printf "%.9f %s %s %s %s %s %s %s\n", $1/1e9, $2, $3, $4, $6, $7, $8, $5}' "$E/mav0/state_groundtruth_estimate0/data.csv" > et/mav0/state_groundtruth_estimate0/data.csv
mke em; rm -rf em/mav0/cam1
mke enogt; rm -rf enogt/mav0/state_groundtruth_estimate0
mke ey
mkk() {  # mkk DIR: KITTI 06 (51 frames) with calib, times and poses copied, images linked
  rm -rf "$1"; mkdir -p "$1/poses" "$1/sequences/06"; cp "$K/poses/06.txt" "$1/poses/"
  cp "$K/sequences/06/calib.txt" "$K/sequences/06/times.txt" "$1/sequences/06/"
  ln -s "$K/sequences/06/image_0" "$1/sequences/06/image_0"; ln -s "$K/sequences/06/image_1" "$1/sequences/06/image_1"; }
mkk kt; sed -i '5s/.*/1.0e-01/' kt/sequences/06/times.txt
mkk kt2; sed -i '$d' kt2/sequences/06/times.txt
mkk kc; sed -i '/^P1:/d' kc/sequences/06/calib.txt
mkk kc2; sed -i 's/^P1: \(\S* \S* \S*\) \S*/P1: \1 0.000000000000e+00/' kc2/sequences/06/calib.txt
mkk ki; rm ki/sequences/06/image_1; mkdir ki/sequences/06/image_1; for x in "$K/sequences/06/image_1/"*.png; do ln -s "$x" ki/sequences/06/image_1/; done; rm ki/sequences/06/image_1/000007.png
mkk kp; sed -i '3s/ [^ ]*$/ abc/' kp/poses/06.txt
grep -v '^#' "$R/freiburg1_xyz-groundtruth.txt" > gt_repeat.txt; sed -n 400p gt_repeat.txt >> gt_repeat.txt; sort -s -k1,1n gt_repeat.txt -o gt_repeat.txt
tac "$R/freiburg1_xyz-rgbdslam.txt" > est_rev.txt
: > empty.txt; echo "1 2 3" > three.txt; echo "1 0 0 0 0 0 0 1" > one.txt; printf '1 0 0 inf 0 0 0 1\n2 0 0 0 0 0 0 1\n' > inf.txt
awk -F, 'NR>1' "$E/mav0/state_groundtruth_estimate0/data.csv" > euroc_gt17.txt
head -c 5000 "$root/vocabulary/"*.bin > vocab_cut.bin 2>/dev/null || true
vocab=$(ls "$root/vocabulary/"*.bin 2>/dev/null | head -1)
if [[ -n $vocab ]]; then cp "$vocab" vocab_flip.bin; printf '\x55' | dd of=vocab_flip.bin bs=1 seek=100000 conv=notrunc status=none; fi
printf 'not a vocabulary' > vocab_text.bin
head -c 3000 /dev/urandom > junk.map
tail -n +2 "$root/examples/settings/TUM3.yaml" > settings_nohdr.yaml
sed 's/^Camera.fx:.*/Camera.fx: -500/' "$root/examples/settings/TUM3.yaml" > settings_negfx.yaml
sed 's/^ORBextractor.nFeatures:.*/ORBextractor.nFeatures: 100000000/' "$root/examples/settings/TUM3.yaml" > settings_hugefeat.yaml
sed 's/^ORBextractor.nLevels:.*/ORBextractor.nLevels: 0/' "$root/examples/settings/TUM3.yaml" > settings_levels0.yaml
cp "$root/tests/fuzz/corpus/settings_yaml/crash-opencv-filestorage-hang.yaml" settings_hang.yaml
cp "$root/tests/fuzz/corpus/bal/crash-huge-counts.txt" huge.bal
# A real map file (TUM teddy, 60 frames) for the map rows, and damaged copies of it.
"$B" run tum "$TD" --settings "$root/examples/settings/TUM3.yaml" --max-frames 60 --save-map teddy.map --out good >/dev/null 2>&1
head -c $(( $(stat -c %s teddy.map) / 2 )) teddy.map > map_cut.map
cp teddy.map map_flip.map; printf '\x55' | dd of=map_flip.map bs=1 seek=5000 conv=notrunc status=none
"$B" synth synth_small --frames 20 --width 320 --height 240 --fx 250 >/dev/null 2>&1
echo "existing map" > existing.map

# --- the table -------------------------------------------------------------------------------
echo "| # | input | what orbis said | exit | on disk |"
echo "|---|---|---|---|---|"
T3="--settings $root/examples/settings/TUM3.yaml"
row "EuRoC slice with ASL's sensor.yaml (no %YAML:1.0 line), cam0 and cam1" o_asl "$B" run euroc asl --max-frames 40 --out o_asl
row "eval ate: TUM ground truth (fr1/xyz) with a row repeated (as fr2/desk line 10,863)" - "$B" eval ate gt_repeat.txt "$R/freiburg1_xyz-rgbdslam.txt"
row "TUM teddy, depth.txt lists nothing (rgb only)" o "$B" run tum tum_nodepth --out o
row "TUM teddy without depth.txt" o "$B" run tum tum_nodepthlist --out o
row "TUM teddy without depth.txt, --sensor mono" o "$B" run tum tum_nodepthlist --sensor mono --max-frames 40 --out o
row "TUM teddy, depth/ deleted (depth.txt intact)" o "$B" run tum tum_nodepthdir --out o
row "TUM teddy, rgb.txt rows shuffled" o "$B" run tum tum_shuffled --max-frames 40 --out o
row "TUM teddy, rows of rgb.txt and groundtruth.txt repeated at the end" o "$B" run tum tum_rep --max-frames 40 --out o
row "TUM rgb.txt with comments only" o "$B" run tum tum_empty --out o
row "TUM: every rgb PNG missing" o "$B" run tum tum_norgb --out o
row "TUM depth.txt naming 8-bit colour PNGs as depth maps" o "$B" run tum tum_8bit --out o
row "TUM rgb.txt with CRLF line ends" o "$B" run tum tum_crlf --max-frames 20 --out o
row "TUM rgb.txt, line 10's timestamp 'nan'" o "$B" run tum tum_nan --max-frames 20 --out o
row "TUM teddy with --sensor stereo" o "$B" run tum "$TD" --sensor stereo --out o
row "EuRoC: cam0 PNG of frame 10 and cam1 PNG of frame 20 deleted, cam0 PNG of frame 30 cut to 3 kB, cam1 PNG of frame 40 empty" o "$B" run euroc e_badpng --max-frames 45 --out o
printf '# sensor\nintrinsics: [458.6, 457.3, 367.2\nresolution: [752, 480]\n' > ey/mav0/cam0/sensor.yaml
row "EuRoC sensor.yaml with an unclosed [ list" o "$B" run euroc ey --out o
: > ey/mav0/cam0/sensor.yaml; row "EuRoC sensor.yaml empty" o "$B" run euroc ey --out o
printf -- '- a\n- b\n' > ey/mav0/cam0/sensor.yaml; row "EuRoC sensor.yaml a YAML list" o "$B" run euroc ey --out o
tail -n +2 "$E/mav0/cam0/sensor.yaml" | sed 's/camera_model: pinhole/camera_model: omni/' > ey/mav0/cam0/sensor.yaml; row "EuRoC sensor.yaml camera_model: omni" o "$B" run euroc ey --out o
tail -n +2 "$E/mav0/cam0/sensor.yaml" | sed 's/^intrinsics:.*/intrinsics: [458.6, abc, 367.2, 248.3]/' > ey/mav0/cam0/sensor.yaml; row "EuRoC sensor.yaml intrinsics with a word" o "$B" run euroc ey --out o
tail -n +2 "$E/mav0/cam0/sensor.yaml" | sed 's/^intrinsics:.*/intrinsics: [458.6, .nan, 367.2, 248.3]/' > ey/mav0/cam0/sensor.yaml; row "EuRoC sensor.yaml intrinsics with .nan" o "$B" run euroc ey --out o
tail -n +2 "$E/mav0/cam0/sensor.yaml" | sed 's/  rows: 4/  rows: 3/' > ey/mav0/cam0/sensor.yaml; row "EuRoC sensor.yaml T_BS rows: 3" o "$B" run euroc ey --out o
tail -n +2 "$E/mav0/cam0/sensor.yaml" | sed 's/^resolution:.*/resolution: [752.5, 480]/' > ey/mav0/cam0/sensor.yaml; row "EuRoC sensor.yaml resolution [752.5, 480]" o "$B" run euroc ey --out o
printf '\xff\xfe\x00garbage: [' > ey/mav0/cam0/sensor.yaml; row "EuRoC sensor.yaml binary garbage" o "$B" run euroc ey --out o
row "EuRoC cam0/data.csv rows in reverse order" o "$B" run euroc eo --max-frames 40 --out o
row "EuRoC cam0/data.csv with a timestamp written 1.4e18" o "$B" run euroc ef --out o
row "EuRoC ground truth data.csv in TUM form (seconds, spaces)" o "$B" run euroc et --max-frames 40 --out o
row "EuRoC without mav0/cam1" o "$B" run euroc em --out o
row "EuRoC without ground truth (state_groundtruth_estimate0)" o "$B" run euroc enogt --max-frames 30 --out o
row "KITTI times.txt with a row earlier than the previous" o "$B" run kitti kt --out o
row "KITTI times.txt one row short of the images" o "$B" run kitti kt2 --out o
row "KITTI calib.txt without P1" o "$B" run kitti kc --out o
row "KITTI calib.txt P1 with zero baseline" o "$B" run kitti kc2 --out o
row "KITTI image_1/000007.png missing" o "$B" run kitti ki --out o
row "KITTI poses/06.txt with a word on line 3" o "$B" run kitti kp --out o
row "run kitti-raw on a folder without image_00" o "$B" run kitti-raw "$TD" --out o
row "run kitti on a TUM folder" o "$B" run kitti "$TD" --out o
row "run euroc on a KITTI folder" o "$B" run euroc "$K" --out o
row "eval ate: EuRoC 17-column ground truth named .txt" - "$B" eval ate euroc_gt17.txt "$E/mav0/state_groundtruth_estimate0/data.csv"
row "eval ate: EuRoC ground truth in TUM form named .csv" - "$B" eval ate et/mav0/state_groundtruth_estimate0/data.csv "$E/mav0/state_groundtruth_estimate0/data.csv"
row "eval ate: estimate rows in reverse order" - "$B" eval ate "$R/freiburg1_xyz-groundtruth.txt" est_rev.txt
row "eval ate: a file of 3-column rows" - "$B" eval ate three.txt three.txt
row "eval ate: empty files" - "$B" eval ate empty.txt empty.txt
row "eval ate: ground truth missing" - "$B" eval ate nothere.txt "$R/freiburg1_xyz-rgbdslam.txt"
row "eval ate: a directory as ground truth" - "$B" eval ate "$W" "$R/freiburg1_xyz-rgbdslam.txt"
row "eval ate: a row with inf" - "$B" eval ate inf.txt inf.txt
row "eval ate: one pose each" - "$B" eval ate one.txt one.txt
row "eval ate: no common time (TUM vs EuRoC)" - "$B" eval ate "$R/freiburg1_xyz-groundtruth.txt" "$E/mav0/state_groundtruth_estimate0/data.csv"
row "eval ate --max-dt -1" - "$B" eval ate "$R/freiburg1_xyz-groundtruth.txt" "$R/freiburg1_xyz-rgbdslam.txt" --max-dt -1
row "eval ate --format bal" - "$B" eval ate "$R/freiburg1_xyz-groundtruth.txt" "$R/freiburg1_xyz-rgbdslam.txt" --format bal
row "run tum --settings: no %YAML:1.0 line" o "$B" run tum "$TD" --settings settings_nohdr.yaml --max-frames 20 --out o
row "run tum --settings: Camera.fx: -500" o "$B" run tum "$TD" --settings settings_negfx.yaml --out o
row "run tum --settings: ORBextractor.nFeatures: 100000000" o "$B" run tum "$TD" --settings settings_hugefeat.yaml --max-frames 5 --out o
row "run tum --settings: ORBextractor.nLevels: 0" o "$B" run tum "$TD" --settings settings_levels0.yaml --out o
row "run tum --settings: 724-byte damaged file that hangs cv::FileStorage" o "$B" run tum "$TD" --settings settings_hang.yaml --out o
row "run tum --settings /nonexistent.yaml" o "$B" run tum "$TD" --settings /nonexistent.yaml --out o
row "run tum --vocab /nonexistent.bin" o "$B" run tum "$TD" --vocab /nonexistent.bin --out o
row "run tum --vocab: vocabulary cut to 5 kB" o "$B" run tum "$TD" --vocab vocab_cut.bin --out o
row "run tum --vocab: one byte of the vocabulary changed" o "$B" run tum "$TD" --vocab vocab_flip.bin --out o
row "run tum --vocab: a text file" o "$B" run tum "$TD" --vocab vocab_text.bin --out o
row "run tum --load-map: 3 kB of random bytes" o "$B" run tum "$TD" $T3 --load-map junk.map --localize --out o
row "run tum --load-map: a real map cut in half" o "$B" run tum "$TD" $T3 --load-map map_cut.map --out o
row "run tum --load-map: a real map with one byte changed" o "$B" run tum "$TD" $T3 --load-map map_flip.map --out o
row "run tum --load-map: map of another camera (rendered sequence)" o "$B" run tum synth_small --settings synth_small/settings.yaml --load-map teddy.map --out o
row "run tum --load-map /nonexistent.map" o "$B" run tum "$TD" $T3 --load-map /nonexistent.map --out o
row "run tum --save-map over an existing file, run fails (no depth)" o "$B" run tum tum_nodepth --save-map existing.map --out o
[[ "$(cat existing.map)" == "existing map" ]] && echo "|   | (existing.map after the row above) | unchanged | | kept |"
row "run tum --save-map /proc/x/m.map (unwritable)" o "$B" run tum "$TD" $T3 --max-frames 5 --save-map /proc/x/m.map --out o
row "run tum --out /proc/x (unwritable)" - "$B" run tum "$TD" --max-frames 3 --out /proc/x
row "run tum --out naming an existing file" - "$B" run tum "$TD" --max-frames 3 --out empty.txt
row "run tum --max-frames -1" o "$B" run tum "$TD" --max-frames -1 --out o
row "run tum --max-frames abc" o "$B" run tum "$TD" --max-frames abc --out o
row "run tum --sensor lidar" o "$B" run tum "$TD" --sensor lidar --out o
row "run tum --frobnicate" o "$B" run tum "$TD" --frobnicate --out o
row "run tum /nonexistent" o "$B" run tum /nonexistent --out o
row "run bonn PATH (unknown dataset kind)" o "$B" run bonn "$TD" --out o
row "run (no arguments)" - "$B" run
row "orbis frobnicate (unknown command)" - "$B" frobnicate
row "view a map cut in half" - timeout 20 "$B" view map_cut.map
row "ba on a BAL file announcing 2377900603251621882 observations" - "$B" ba huge.bal
row "synth --frames 0" - "$B" synth synth_zero --frames 0
row "synth --width 7" - "$B" synth synth_w7 --width 7
