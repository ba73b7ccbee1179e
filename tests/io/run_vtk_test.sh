#!/usr/bin/env bash
# Runs a small twisting column twice (binary and ASCII VTK) and checks both
# with VTK's own reader (check_vtk.py, Debian's /usr/bin/python3 with
# python3-vtk9). 3 x 7 x 3 particles: too coarse for the zig-zag indicator
# to judge.
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
/usr/bin/python3 "$(dirname "$0")/check_vtk.py" "$work/bin" "$work/ascii" twisting_column
