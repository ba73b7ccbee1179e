#!/usr/bin/env bash
# Re-makes the frame images of outputs/gallery/ from the shipped scenes as
# they are (each image one frame of `sph run SCENE`, with the scene's own
# settings; punch and coining have no output.png block, so theirs is the
# default one), and one short animation per headline scene (twisting_column,
# colliding_rings, punch) as outputs/gallery/SCENE.mp4 (*.mp4 is git-ignored
# there: those under 2 MiB are added by hand), then checks the sizes. The plots of outputs/gallery
# (*_energy, *_convergence, *_error_vs_time) come from studies/, not from here.
#
# usage: tools/gallery/make_gallery.sh [--sph PATH] [--threads N] [SCENE]...
#   default: every scene below, one after another, with build/sph; each run
#   writes outputs/SCENE/ (replacing it) and prints its wall time.
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
sph=$root/build/sph
threads=()
scenes=()
while [ $# -gt 0 ]; do
  case "$1" in
  --sph) sph=$(realpath "$2"); shift 2 ;;
  --threads) threads=(--threads "$2"); shift 2 ;;
  -h | --help) sed -n '2,12p' "$0"; exit 0 ;;
  *) scenes+=("$1"); shift ;;
  esac
done
[ ${#scenes[@]} -gt 0 ] ||
  scenes=(twisting_column colliding_rings punch coining oring_squeeze dogbone_tensile)

# SCENE: the run's --set options | frame number:gallery image ... | mp4 (yes/no)
# The animations are played at 12 frames/s (fps changes only the mp4).
anim='--set output.png.fps=12'
declare -A sets frames mp4
sets[twisting_column]="$anim";      frames[twisting_column]="50:twisting_column"
sets[colliding_rings]="$anim";      frames[colliding_rings]="12:colliding_rings 40:colliding_rings_after_rebound"
sets[punch]="--set 'output.png={fps: 12}'"; frames[punch]="70:punch"
sets[coining]="--set output.png=true"; frames[coining]="46:coining"
sets[oring_squeeze]="";             frames[oring_squeeze]="50:oring_squeeze"
sets[dogbone_tensile]="";           frames[dogbone_tensile]="40:dogbone_tensile"
mp4[twisting_column]=yes; mp4[colliding_rings]=yes; mp4[punch]=yes
cd "$root"

png_max=$((1024 * 1024))     # a gallery image stays under 1 MiB
mp4_max=$((2 * 1024 * 1024)) # an animation over 2 MiB is reported: keep it out of git
fail=0
gal=outputs/gallery
mkdir -p "$gal"
start=$(date +%s)
for s in "${scenes[@]}"; do
  [ -n "${frames[$s]+x}" ] || { echo "unknown gallery scene: $s" >&2; exit 2; }
  # shellcheck disable=SC2086
  cmd="$sph run $s ${sets[$s]} ${threads[*]:-} --overwrite --quiet"
  echo "== $cmd"
  t0=$(date +%s)
  eval "$cmd"
  echo "   $s: $(($(date +%s) - t0)) s wall"
  for f in ${frames[$s]}; do
    n=${f%%:*} img=${f#*:}
    src=$(printf 'outputs/%s/frames/%s_%04d.png' "$s" "$s" "$n")
    [ -f "$src" ] || { echo "missing frame $src" >&2; fail=1; continue; }
    cp "$src" "$gal/$img.png"
    size=$(stat -c %s "$gal/$img.png")
    echo "   $gal/$img.png <- $src ($size bytes)"
    [ "$size" -le $png_max ] || { echo "   too large: over $png_max bytes" >&2; fail=1; }
  done
  if [ "${mp4[$s]:-no}" = yes ]; then
    if [ -f "outputs/$s/$s.mp4" ]; then
      cp "outputs/$s/$s.mp4" "$gal/$s.mp4"
      size=$(stat -c %s "$gal/$s.mp4")
      echo "   $gal/$s.mp4 ($size bytes$([ "$size" -le $mp4_max ] || echo ', over 2 MiB: not for git'))"
    else
      echo "   no mp4 (ffmpeg missing? ./bootstrap.sh --with-ffmpeg)" >&2
      fail=1
    fi
  fi
done
echo "== ${#scenes[@]} scene(s) in $(($(date +%s) - start)) s wall; sizes $([ $fail -eq 0 ] && echo ok || echo NOT ok)"
exit $fail
