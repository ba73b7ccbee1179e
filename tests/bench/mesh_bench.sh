#!/bin/sh
# Mesh fill speed: a sphere of at least 100k triangles (binary STL, made by
# tests/data/meshes/make_meshes.py) filled with about 1M particles, on 1 and
# 2 threads. Usage: tests/bench/mesh_bench.sh [BUILD_DIR]
set -eu
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../../build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 "$here/../data/meshes/make_meshes.py" --big 100000 "$tmp/ball.stl"
for t in 1 2; do
  OMP_NUM_THREADS=$t "$build/tests/mesh_bench" "$tmp/ball.stl" 0.00806
done
