#!/usr/bin/env bash
# frames.sh SPH OUT: a mid-run frame of each headline scene, cut down to
# run in seconds (coarser particles, an earlier end, 320x180 frames), drawn
# with the defaults of the PNG sink (one colour range and one camera per
# run), copied to OUT/<scene>.png. The golden images in tests/golden were
# made by `tests/golden/frames.sh build/sph tests/golden`; the test
# frames_golden (tests/cli/run_frames_tests.sh) runs it again into a
# temporary folder and compares each image with `sph imgdiff`.
set -eu
sph=$1
out=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# scene | its overrides | the mid-run frame
run() {
  local scene=$1 frame=$2
  shift 2
  OMP_NUM_THREADS=1 "$sph" run "$src/scenes/$scene.yaml" --threads 1 --quiet \
    --out "$work/$scene" --set output.png.width=320 \
    --set output.png.height=180 --set output.png.mp4=false \
    --set output.vtk=false "$@" >/dev/null
  cp "$work/$scene/frames/${scene}_$(printf %04d "$frame").png" "$out/$scene.png"
}
# twisting column: 5 x 25 x 5 particles to 0.06 s, frame 3 of 6 (0.03 s)
run twisting_column 3 --set 'bodies.0.particles.count=[5,25,5]' \
  --set time.end=0.06 --set output.every=0.01
# colliding rings: twice the spacing to 0.006 s, frame 4 of 6 (0.004 s,
# the rings pressed together)
run colliding_rings 4 --set bodies.0.particles.spacing=0.002 \
  --set bodies.1.particles.spacing=0.002 --set time.end=0.006 \
  --set output.every=0.001
# punch: as shipped to 0.006 s, frame 3 of 6 (0.003 s)
run punch 3 --set time.end=0.006 --set output.every=0.001
