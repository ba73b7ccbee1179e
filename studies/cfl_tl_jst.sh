#!/usr/bin/env bash
# tl-jst's time step (issue 33, docs/stability.md "Time step"): pF, pFJ and
# pFHJ with TVD-RK2 and SSP-RK3 over CFL 0.3 to 1.5 on the peer's twisting
# column (11 x 61 x 11, omega 105, to 0.5 s: stable?, steps, energy drift),
# the punch (verdict) and the swinging cube (neo-Hookean, dp 1/16: L2 errors
# against the analytic mode). The cube and the punch write one energy frame
# at the end (one in ten for the punch), so that the output interval does
# not cap the step. Extra options pass through (--threads N, --resume);
# STUDIES picks some of: column punch cube (default all three).
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}
out=${OUT:-outputs/cfl_tl_jst}
vary=(--vary method.integrator=tvd-rk2,ssp-rk3
  --vary method.cfl=0.3,0.5,0.7,0.9,1.1,1.3,1.5)
for s in ${STUDIES:-column punch cube}; do
  case $s in
  column)
    "$sph" study scenes/twisting_column.yaml \
      --set 'bodies.0.particles.count=[11,61,11]' --set time.end=0.5 \
      --vary method.fields=pF,pFJ,pFHJ "${vary[@]}" --out "$out/column" "$@"
    ;;
  punch) # pF has no J equation: its eps4_J is 0
    "$sph" study scenes/punch.yaml --set output.every=0.0014 \
      --vary method.fields=pFJ,pFHJ "${vary[@]}" --out "$out/punch" "$@"
    "$sph" study scenes/punch.yaml --set output.every=0.0014 \
      --set method.jst.eps4_J=0 --vary method.fields=pF "${vary[@]}" \
      --out "$out/punch_pF" "$@"
    ;;
  cube)
    "$sph" study scenes/swinging_cube.yaml \
      --set materials.elastic.model=neo-hookean --set output.every=0.01601 \
      --set bodies.0.particles.spacing=0.0625 \
      --vary method.fields=pF,pFJ,pFHJ "${vary[@]}" --out "$out/cube" "$@"
    ;;
  *) echo "cfl_tl_jst.sh: unknown study '$s' (column punch cube)" >&2; exit 2 ;;
  esac
done
