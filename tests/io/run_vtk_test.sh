#!/usr/bin/env bash
# Runs a small twisting column twice (binary and ASCII VTK) and checks both
# with VTK's own reader (check_vtk.py, Debian's /usr/bin/python3 with
# python3-paraview's vtkmodules). 3 x 7 x 3 particles: too coarse for the
# zig-zag indicator to judge.
set -u
sph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
common=(--quiet --set 'bodies.0.particles.count=[3,7,3]' --set time.end=0.02
  --set 'output.fields=[pressure,velocity,displacement,initial_position,J,stress,body_id,particle_id,acceleration]')
"$sph" run "$src/scenes/twisting_column.yaml" --out "$work/bin" "${common[@]}" >/dev/null || exit 1
"$sph" run "$src/scenes/twisting_column.yaml" --out "$work/ascii" "${common[@]}" \
  --set output.vtk.format=ascii >/dev/null || exit 1
/usr/bin/python3 "$(dirname "$0")/check_vtk.py" "$work/bin" "$work/ascii" twisting_column || exit 1
# zlib-compressed appended data: VTK's reader gives the same arrays as the
# ASCII files, the files are smaller, and sph render reads them back
"$sph" run "$src/scenes/twisting_column.yaml" --out "$work/zlib" "${common[@]}" \
  --set 'output.vtk={compress: zlib}' --set 'output.png={width: 160, height: 120, mp4: false}' \
  >/dev/null || exit 1
/usr/bin/python3 "$(dirname "$0")/check_vtk.py" "$work/zlib" "$work/ascii" twisting_column || exit 1
zsize=$(cat "$work"/zlib/*.vtp | wc -c)
bsize=$(cat "$work"/bin/*.vtp | wc -c)
[ "$zsize" -lt "$bsize" ] || { echo "FAIL: zlib files ($zsize bytes) not smaller than raw ($bsize)"; exit 1; }
"$sph" render "$work/zlib" --out "$work/zr" >/dev/null || { echo "FAIL: sph render of zlib files"; exit 1; }
cmp -s "$work/zlib/frames/twisting_column_0004.png" "$work/zr/frames/twisting_column_0004.png" ||
  { echo "FAIL: the frame drawn again from zlib files differs"; exit 1; }
echo "zlib: $zsize bytes against $bsize raw"

