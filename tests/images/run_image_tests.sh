#!/usr/bin/env bash
# Golden images (CTest label images): small runs of shipped scenes rendered
# by `sph run` (320x240, one thread) and compared frame by frame with the
# committed tests/images/<case>_NNNN.png by `sph imgdiff` (its defaults:
# tolerance 16, shift 1). A missing, extra or different frame fails; the
# frames and difference images of a failure are kept in ./images_failed.
#
#   tests/images/run_image_tests.sh [SPH [SOURCE_DIR]]       compare
#   tests/images/run_image_tests.sh --regenerate             rewrite goldens
#
# SPH defaults to SOURCE_DIR/build/sph, SOURCE_DIR to the repository. A new
# scene is one image_case line at the end of this file.
set -u
regen=0
args=()
for a in "$@"; do
  if [ "$a" = --regenerate ]; then regen=1; else args+=("$a"); fi
done
here=$(cd "$(dirname "$0")" && pwd)
src=${args[1]:-$(cd "$here/../.." && pwd)}
sph=${args[0]:-$src/build/sph}
failed_dir=${IMAGE_TEST_OUT:-$PWD/images_failed}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
common=(--quiet --threads 1 --set output.vtk=false --set output.png.mp4=false
  --set output.png.width=320 --set output.png.height=240)
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# image_case NAME SCENE [--set key=value]...: runs SCENE (relative to the
# repository) and checks its frames against NAME_NNNN.png
image_case() {
  local name=$1 scene=$2 out=$work/$1
  shift 2
  local t0=$SECONDS
  if ! "$sph" run "$src/$scene" --out "$out" "${common[@]}" "$@" >"$work/log" 2>&1; then
    fail "$name: sph run failed: $(cat "$work/log")"
    return
  fi
  local frames=("$out"/frames/*.png) n=0 i golden
  if [ $regen -eq 1 ]; then
    rm -f "$here/${name}"_[0-9][0-9][0-9][0-9].png
    for f in "${frames[@]}"; do
      cp "$f" "$here/${name}_${f: -8}"
    done
    echo "$name: wrote ${#frames[@]} goldens ($((SECONDS - t0)) s)"
    return
  fi
  for f in "${frames[@]}"; do
    golden=$here/${name}_${f: -8}
    n=$((n + 1))
    if [ ! -f "$golden" ]; then
      fail "$name: no golden $(basename "$golden") (regenerate with --regenerate)"
      continue
    fi
    if ! "$sph" imgdiff "$f" "$golden" --diff "$work/diff.png" >"$work/cmp" 2>&1; then
      fail "$name: $(basename "$golden") differs: $(cat "$work/cmp")"
      mkdir -p "$failed_dir"
      cp "$f" "$failed_dir/${name}_${f: -8}"
      cp "$work/diff.png" "$failed_dir/${name}_diff_${f: -8}" 2>/dev/null
    fi
  done
  i=$(ls "$here/${name}"_[0-9][0-9][0-9][0-9].png 2>/dev/null | wc -l)
  [ "$i" -eq "$n" ] || fail "$name: $n frames rendered, $i goldens"
  echo "$name: $n frames compared ($((SECONDS - t0)) s)"
}

# A1 twisting column, 5x25x5, t = 0, 0.1, 0.2 s
image_case twisting_column scenes/twisting_column.yaml --set "bodies.0.particles.count=[5, 25, 5]" --set time.end=0.2 --set output.every=0.1
# A4 punch, 21x11x3, t = 0, 0.007, 0.014 s, seen from the front
image_case punch scenes/punch.yaml --set "bodies.0.particles.count=[21, 11, 3]" --set time.end=0.014 --set output.every=0.007 --set "output.png.camera={azimuth: 15, elevation: 10, zoom: 0.7}"
# A8 colliding rings (ul-sph, ENOG), dp 0.002, through the rebound to
# 0.03 s: the follow camera keeps both rings in view, left of the bar
image_case colliding_rings scenes/colliding_rings.yaml --set bodies.0.particles.spacing=0.002 --set bodies.1.particles.spacing=0.002 --set time.end=0.03 --set output.every=0.015
# one-sided fields: von Mises (viridis over its own robust range) and J
# (cool-to-warm centred on 1), the twisting column at t = 0.2 s
image_case twisting_column_von_mises scenes/twisting_column.yaml --set "bodies.0.particles.count=[5, 25, 5]" --set time.end=0.2 --set output.every=0.2 --set output.png.color=von_mises
image_case twisting_column_J scenes/twisting_column.yaml --set "bodies.0.particles.count=[5, 25, 5]" --set time.end=0.2 --set output.every=0.2 --set output.png.color=J

echo "$fails failed"
[ $fails -eq 0 ]
