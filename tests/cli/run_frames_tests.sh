#!/usr/bin/env bash
# Golden images of the headline scenes (issue 38): a mid-run frame each of
# the twisting column, the colliding rings and the punch, cut down to run in
# seconds (tests/golden/frames.sh), drawn again and compared with the
# committed 320x180 images by `sph imgdiff` at its defaults: a pixel matches
# when some pixel within one of its place in the other image has every
# channel within 16 of it (llvmpipe's rounding, a sphere's edge moved by a
# pixel), at most 0.1 % of the pixels may not match and no 9 of them
# touch. A wrong colour range, camera, projection, sphere size or overlay
# fails. Usage: run_frames_tests.sh SPH SOURCE_DIR
set -u
sph=$1
src=$2
. "$(dirname "$0")/harness.sh"

"$src/tests/golden/frames.sh" "$sph" "$work" || bad "tests/golden/frames.sh failed"
for scene in twisting_column colliding_rings punch; do
  "$sph" imgdiff "$src/tests/golden/$scene.png" "$work/$scene.png" \
    --diff "$work/${scene}_diff.png" >"$work/stdout" 2>&1 && ok ||
    bad "$scene: frame differs from tests/golden/$scene.png: $(cat "$work/stdout")"
done
echo "frames golden: $pass passed, $fail failed"
[ $fail -eq 0 ]
