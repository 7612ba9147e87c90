# Sourced by the monocular benchmarks (mono_loops.sh, mono_scale_seeds.sh): the rendered scenes
# they share, so both run on the same renders.
# In: SCENE (corridor or room; the caller's default in $1), SIZE="W H FX" (default 320 240 250),
# ORBIS, WORK. Out: orbis, work, scene, width, height, fx, frames, extra;
# render_mono_scene SEED THREADS, which prints the sequence folder (rendered on first use); and
# relative_size GT EST FROM..., the estimate's scale drift.
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
orbis=${ORBIS:-$root/build/release/orbis}
work=${WORK:-$(mktemp -d)}
read -r width height fx <<<"${SIZE:-320 240 250}"
scene=${SCENE:-$1}
case $scene in
  corridor) frames=600 extra=150 ;;  # 27 m at about 1.4 m/s
  room) frames=300 extra=75 ;;
  *) echo "SCENE must be corridor or room" >&2; exit 2 ;;
esac
mkdir -p "$work"

render_mono_scene() {  # SEED THREADS
  local seq=$work/${scene}_${width}x${height}_$1
  [[ -f $seq/settings_mono.yaml ]] || "$orbis" synth "$seq" --scene "$scene" --frames "$frames" --extra "$extra" \
    --width "$width" --height "$height" --fx "$fx" --noise 4 --seed "$1" --threads "$2" >/dev/null
  echo "$seq"
}

# The Sim(3) scale aligning lines [FROM, FROM + COUNT) of trajectory EST to the ground truth GT:
# ground truth over estimate. A temporary file per call, so parallel runs do not meet.
stretch_scale() {  # GT EST FROM COUNT
  local part
  part=$(mktemp)
  grep -v '^#' "$2" | sed -n "$(($3 + 1)),$(($3 + $4))p" >"$part"
  "$orbis" eval ate "$1" "$part" --align sim3 --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["scale"])'
  rm -f "$part"
}

# The estimate's size over its 60 lines from each FROM against its first 60 (each stretch aligned
# to the ground truth on its own), one per FROM on a line: 1 is no scale drift, under 1 the map
# shrank. The first 60 lines are aligned once for all FROMs.
relative_size() {  # GT EST FROM...
  local gt=$1 est=$2 first from
  shift 2
  first=$(stretch_scale "$gt" "$est" 0 60)
  for from in "$@"; do
    python3 -c "print(f'{$first / $(stretch_scale "$gt" "$est" "$from" 60):.3f}')"
  done
}
