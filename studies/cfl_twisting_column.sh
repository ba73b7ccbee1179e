#!/usr/bin/env bash
# Twisting column (scenes/twisting_column.yaml, tl-jst): the CFL number from
# 0.1 to 0.6 (steps, wall time, energy drift, stability), CFL as the
# resolution axis of the report. Extra options pass through (--threads N,
# --repeat N, --resume).
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}
exec "$sph" study scenes/twisting_column.yaml \
  --vary method.cfl=0.1,0.2,0.3,0.4,0.5,0.6 \
  --out outputs/twisting_column_cfl_study "$@"
