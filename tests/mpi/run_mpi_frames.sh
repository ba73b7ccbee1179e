#!/usr/bin/env bash
# PNG frames over MPI ranks (issue 20): every rank draws its own particles,
# the images are composited by depth onto rank 0, and the frames equal the
# serial run's byte for byte on 2 and 3 ranks: the twisting column with
# tl-jst (3D, perspective camera), the rubber rings with ul-csph (2D,
# particles migrating between ranks), and the column with tl-csph cut in
# half, its reference outline (ghost), the follow camera and the grow-only
# range of von Mises stress (viridis); the last resumed on 2 ranks from a
# checkpoint (the camera and range replayed from every rank's pieces)
# gives the serial run's last frame. Usage:
# run_mpi_frames.sh SPH SOURCE_DIR
set -u
sph=$1
# shellcheck source=mpi_common.sh
. "$(dirname "$0")/mpi_common.sh"
small=(--quiet --set output.png.width=320 --set output.png.height=180
  --set output.png.mp4=false)
same_frames() { # serial folder, MPI folder
  local n=0 f
  for f in "$1"/frames/*.png; do
    cmp "$f" "$2/frames/${f##*/}" || return 1
    n=$((n + 1))
  done
  [ $n -gt 0 ] && [ "$(ls "$2/frames" | wc -l)" -eq $n ]
}
frames() { # name, sph args...
  local name=$1
  shift
  OMP_NUM_THREADS=1 "$sph" "$@" --out "$work/$name.serial" >/dev/null ||
    { fail "$name serial run"; return; }
  for n in 2 3; do
    check "$name np $n runs" "${mpi[@]}" -np $n "$sph" "$@" --out "$work/$name.np$n"
    check "$name np $n frames equal serial" same_frames "$work/$name.serial" \
      "$work/$name.np$n"
  done
}

frames jst run twisting_column "${small[@]}" --set 'method={name: tl-jst}' \
  --set 'bodies.0.particles.count=[5,25,5]' --set output.vtk=false \
  --set time.end=0.01 --set output.every=0.005 \
  --set output.png.camera.projection=perspective
frames rings run rubber_rings_ul_csph "${small[@]}" --set output.vtk=false \
  --set time.end=0.001 --set output.every=0.0005
cut=(run twisting_column "${small[@]}" --set 'method={name: tl-csph}'
  --set 'bodies.0.particles.count=[5,25,5]' --set time.end=0.025
  --set output.every=0.005 --set output.checkpoint_every=0.01
  --set output.png.cut=half --set output.png.ghost=true
  --set output.png.camera.follow=true --set output.png.color=von_mises
  --set output.png.range=auto)
frames cut "${cut[@]}"

# resumed from the checkpoint at t = 0.02 (frames 0-4 written): the last
# frame's camera and range come from replaying every rank's pieces (without
# them it differs)
resumed() {
  cp -r "$work/cut.np2" "$work/resumed" &&
    rm "$work/resumed/frames/twisting_column_0005.png" &&
    "${mpi[@]}" -np 2 "$sph" "${cut[@]}" --resume "$work/resumed" &&
    cmp "$work/cut.serial/frames/twisting_column_0005.png" \
      "$work/resumed/frames/twisting_column_0005.png"
}
check "cut np 2 resumed: the last frame equals serial" resumed
summary
