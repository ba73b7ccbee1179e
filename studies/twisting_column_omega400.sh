#!/usr/bin/env bash
# The peer's extreme twist (issue 14 item 4a; seed 004 Fig. 25): the A1
# column at Omega = 400 rad/s with seed 004's method (tl-bond, bond F,
# SSP-RK3, CFL 0.5, eta4 = 1/8, h = 1.1 dp) at the paper's 12 x 12 x 72, to
# the peer's 0.5 s, and tl-jst {p,F} on the same lattice for comparison
# with the same kernel and fracture threshold. About 12 minutes on 2 threads for
# tl-bond. Extra options pass through to sph study (--threads N, --resume,
# --dry-run).
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}
exec "$sph" study scenes/twisting_column_bond.yaml \
  --set bodies.0.initial_velocity.rotation.omega=400 \
  --set 'bodies.0.particles.count=[12,72,12]' \
  --set time.end=0.5 --set output.png=false \
  --vary 'method={name: tl-bond, cfl: 0.5},{name: tl-jst, fields: pF, cfl: 0.3, angular_momentum_projection: true}' \
  --out outputs/twisting_column_omega400 "$@"
