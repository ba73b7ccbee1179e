#!/usr/bin/env bash
# Oscillating plate 2D (scenes/oscillating_plate_2d.yaml, ul-sph): dual
# against single time stepping at two particle spacings. Extra options pass
# through (--threads N, --repeat N, --resume).
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}
exec "$sph" study scenes/oscillating_plate_2d.yaml \
  --vary method.time_stepping=dual,single \
  --vary bodies.0.particles.spacing=0.002,0.001 \
  --out outputs/oscillating_plate_2d_study "$@"
