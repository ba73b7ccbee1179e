#!/usr/bin/env bash
# A scene's `reference:` over MPI ranks: the oscillating plate (ul-sph, its
# period measured at the tip against theory) as shipped but for its end time
# (0.3 s: two zero crossings of the tip, one measured period) and the
# particle ids in its fields, on 2 ranks: rank 0 observes the tip in the
# gathered set, so summary.json gives the serial period, error and verdict,
# and the files are the serial ones (check_mpi.py: fields and probes
# identical, energies to 1e-12). The analytic references (they set the
# initial state) run over ranks too: run_mpi_symmetry.sh (the swinging cube);
# here the swinging plate at d = 0.1 with `norm: gauss`: rank 0 gathers the
# particles for seed 004's Gauss-point norms, which come out with the serial
# bits, as do the nodal errors beside them.
# Usage: run_mpi_reference.sh SPH SOURCE_DIR
set -u
sph=$1
src=$2
# shellcheck source=mpi_common.sh
. "$src/tests/mpi/mpi_common.sh"
plate=(run oscillating_plate_2d --quiet --set time.end=0.3
  --set 'output.fields=[velocity,displacement,pressure,von_mises,particle_id]')
compare plate oscillating_plate_2d 1e-12 2 -- "${plate[@]}"
verdict() { # the verdict and the reference's error block of a run
  grep -E '"(stable|error)"' "$1/summary.json"
}
same_verdict() {
  verdict "$work/plate.serial" | grep -q '"period": 0\.2' &&
    [ "$(verdict "$work/plate.serial")" = "$(verdict "$work/plate.np2")" ]
}
check "plate np 2: the serial period and verdict" same_verdict
verdict "$work/plate.np2"
gauss=(run swinging_plate_2d --quiet --set reference.norm=gauss
  --set output.png=false --set output.vtk=false
  --set bodies.0.particles.spacing=0.1)
same_gauss() {
  "$sph" "${gauss[@]}" --threads 1 --out "$work/gauss.serial" &&
    "${mpi[@]}" -np 2 "$sph" "${gauss[@]}" --out "$work/gauss.np2" &&
    verdict "$work/gauss.serial" | grep -q '"l2_displacement_gauss": 0\.000' &&
    [ "$(verdict "$work/gauss.serial")" = "$(verdict "$work/gauss.np2")" ]
}
check "swinging plate np 2: the serial Gauss-point and nodal errors" same_gauss
verdict "$work/gauss.np2"
summary
