#!/usr/bin/env bash
# B1 swinging cube (scenes/swinging_cube.yaml, analytic reference): L2 errors
# and convergence orders of tl-jst {p,F}, {p,F,J}, {p,F,H,J} and tl-csph at
# four particle spacings (64 to 13824 particles), with the neo-Hookean
# material of seed 000 Fig. 6 (the scene's linear-elastic law reads neither J
# nor H, which would make the three field sets identical). Extra options
# pass through, e.g. ./studies/swinging_cube.sh --threads 2 --repeat 3.
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}
jst='name: tl-jst, jst: {eps2_p: 0, eps4_p: 0.125}, angular_momentum_projection: false, jst_projection: false, cfl: 0.3'
exec "$sph" study scenes/swinging_cube.yaml \
  --set materials.elastic.model=neo-hookean \
  --vary "method={fields: pF, $jst},{fields: pFJ, $jst},{fields: pFHJ, $jst},{name: tl-csph, cfl: 0.3}" \
  --vary bodies.0.particles.spacing=0.25,0.125,0.0625,0.041666666666666667 \
  --out outputs/swinging_cube_study "$@"
