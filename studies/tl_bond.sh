#!/usr/bin/env bash
# What the accuracy of seed 004's method costs (issue 19): tl-jst ({p,F},
# TVD-RK2, eq. 44 time step) against tl-bond (bond F, SSP-RK3, pair wave
# speed) at CFL 0.3, 0.6 and 0.9
#  - on the A1 twisting column (scenes/twisting_column.yaml, 7 x 37 x 7, to
#    0.3 s) with the shipped kernel (h = 1.3 dp) and h = 1.1 dp: stable?,
#    steps, wall time;
#  - on the B6 swinging plate (scenes/swinging_plate_2d.yaml, linear
#    elastic: the exact solution's material) at d = 0.1 and 0.05: L2 and H1
#    displacement errors, wall time;
#  - B8 and B10 below.
# Each writes results.csv, report.md and plots under outputs/. Extra
# options pass through to sph study (--threads N, --repeat N, --resume,
# --dry-run).
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}
methods='{name: tl-jst, fields: pF, jst: {eps2_p: 0, eps4_p: 0.125}, integrator: tvd-rk2},{name: tl-bond, jst: {eps2_p: 0, eps4_p: 0.125}}'
"$sph" study scenes/twisting_column.yaml \
  --set output.png=false \
  --vary "method=$methods" \
  --vary method.cfl=0.3,0.6,0.9 \
  --vary kernel.h_over_dp=1.3,1.1 \
  --out outputs/tl_bond_twisting_column "$@"
plate='{name: tl-jst, fields: pF, jst: {eps2_p: 0, eps4_p: 0.125}, integrator: tvd-rk2, angular_momentum_projection: false, jst_projection: false},{name: tl-bond, jst: {eps2_p: 0, eps4_p: 0.125}}'
"$sph" study scenes/swinging_plate_2d.yaml \
  --set materials.rubber.model=linear-elastic \
  --vary "method=$plate" \
  --vary method.cfl=0.3,0.6,0.9 \
  --vary bodies.0.particles.spacing=0.1,0.05 \
  --out outputs/tl_bond_swinging_plate "$@"
# B8 column energy (seed 004 sec. 5.3: about 1 % lost) and B10 pulling
# column (sec. 5.4: stretch at the first NaN; here the time the verdict
# stops the run, stretch = 10 t / 6 x 100 %, with the fracture indicator
# off as the paper's criterion is a NaN), tl-bond at h = 1.1 dp
bond='{name: tl-bond, jst: {eps2_p: 0, eps4_p: 0.125}},{name: tl-bond, jst: {eps2_p: 0, eps4_p: 0.125}, correction: zeroth_order}'
"$sph" study scenes/column_energy.yaml \
  --set kernel.h_over_dp=1.1 --set output.png=false \
  --vary "method={name: tl-jst, fields: pF, jst: {eps2_p: 0, eps4_p: 0.125}, cfl: 0.3},$bond" \
  --out outputs/tl_bond_column_energy "$@"
pull='{name: tl-bond, jst: {eps2_p: 0, eps4_p: 0.015625}},{name: tl-bond, jst: {eps2_p: 0, eps4_p: 0.015625}, correction: zeroth_order}'
"$sph" study scenes/pulling_column.yaml \
  --set kernel.h_over_dp=1.1 --set time.end=3 --set stability.fracture_dp=100 \
  --set output.png=false --set output.vtk=false \
  --vary "method={name: tl-jst, fields: pF, jst: {eps2_p: 0, eps4_p: 0.015625}, cfl: 0.3},$pull" \
  --vary materials.rubber.poisson_ratio=0.45,0.495 \
  --out outputs/tl_bond_pulling_column "$@"
