#!/usr/bin/env bash
# Oscillating plate 2D (scenes/oscillating_plate_2d.yaml, ul-sph ENOG): dual
# against single time stepping at H/dp = 10, 20, 30 (seed 002 Tables 1-2),
# to t = 0.3 s (the first period; the scene's `reference:` measures it
# against thin-plate theory, 0.254). Extra options pass
# through (--threads N, --repeat N, --resume).
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}
exec "$sph" study scenes/oscillating_plate_2d.yaml \
  --vary method.time_stepping=dual,single \
  --set time.end=0.3 \
  --vary bodies.0.particles.spacing=0.002,0.001,0.00066666666666666667 \
  --out outputs/oscillating_plate_2d_study "$@"
