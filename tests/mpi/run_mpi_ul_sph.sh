#!/usr/bin/env bash
# ul-sph over MPI ranks (mpirun, oversubscribed on the machine's cores): the
# colliding rings as shipped, to 0.004 s (the rings touch at about 0.003 s),
# their `relax` particles relaxed per rank (each rank its slice of each
# ring, with the other ranks' points as ghosts), on 2, 3 and 4 ranks give
# the serial run's files (check_mpi.py: the .pvtp
# series read by VTK with the serial particles and arrays, fields and frames
# identical, energies to 1e-12 relative: sums over ranks in another order);
# the 3-rank cut crosses the left ring, so particles migrate and the ranks
# re-balance (summary.json counts them); the same rank count twice writes
# the same bytes; a relaxed ball on a plate on 2 and 3 ranks equals its
# serial run; the stretched plate with its clamped base on 2 and 4 ranks
# equals its serial run too, and on 4 ranks resumes from its checkpoint to
# the same bytes. Usage: run_mpi_ul_sph.sh SPH SOURCE_DIR
set -u
sph=$1
src=$2
# shellcheck source=mpi_common.sh
. "$src/tests/mpi/mpi_common.sh"
run=(run colliding_rings --quiet --set time.end=0.004
  --set output.every=0.001 --set output.png.width=320
  --set output.png.height=180 --set output.png.mp4=false
  --set 'output.fields=[velocity,pressure,von_mises,density,body_id,particle_id]')

OMP_NUM_THREADS=1 "$sph" "${run[@]}" --out "$work/serial" >/dev/null ||
  { echo "FAIL serial run"; exit 1; }
for n in 2 3 4; do
  check "np $n runs" "${mpi[@]}" -np $n "$sph" "${run[@]}" --out "$work/np$n"
  check "np $n equals serial" /usr/bin/python3 "$src/tests/mpi/check_mpi.py" \
    "$work/serial" "$work/np$n" colliding_rings $n 1e-12
  cat "$work/out.txt"
done

# the 3-rank run moves particles between ranks and cuts them again
moved() {
  grep -E '"(migrated|rebalances|halo_rebuilds)"' "$work/np3/summary.json"
  grep -Eq '"migrated": [1-9]' "$work/np3/summary.json" &&
    grep -Eq '"rebalances": [1-9]' "$work/np3/summary.json"
}
check "np 3 migrates and re-balances" moved
cat "$work/out.txt"

# the same rank count and thread count: the same bytes
check "np 3 again" "${mpi[@]}" -np 3 "$sph" "${run[@]}" --out "$work/np3b"
check "np 3 twice: identical files" same_bytes "$work/np3" "$work/np3b"

# a relaxed ball on a lattice plate with clamped ends (relax and lattice
# bodies and selections in one per-rank set-up) on 2 and 3 ranks
ball=(run ball_plate_2d --quiet --set time.end=0.0003 --set output.every=0.0001
  --set output.png=false
  --set 'output.fields=[velocity,pressure,von_mises,density,particle_id]')
compare ball ball_plate_2d 1e-12 2 3 -- "${ball[@]}"

# a clamped base whose particles migrate (the boundary's particle sets
# follow them): the stretched plate on 2 and 4 ranks
plate=(run tensile_plate_2d --quiet --set output.every=0.001
  --set 'output.fields=[velocity,displacement,pressure,von_mises,particle_id]')
OMP_NUM_THREADS=1 "$sph" "${plate[@]}" --out "$work/plate" >/dev/null ||
  { echo "FAIL serial plate"; exit 1; }
for n in 2 4; do
  check "plate np $n runs" "${mpi[@]}" -np $n "$sph" "${plate[@]}" \
    --out "$work/plate$n"
  check "plate np $n equals serial" /usr/bin/python3 \
    "$src/tests/mpi/check_mpi.py" "$work/plate" "$work/plate$n" \
    tensile_plate_2d $n 1e-12
  cat "$work/out.txt"
done
plate_moved() { grep -Eq '"migrated": [1-9]' "$work/plate4/summary.json"; }
check "plate np 4 migrates" plate_moved

# its checkpoint at 0.002 s (after hundreds of migrations and re-balances):
# --resume on 4 ranks gives the uninterrupted run's bytes (the clamped
# base's particle sets follow the restored partition)
resumed_plate() {
  "${mpi[@]}" -np 4 "$sph" "${plate[@]}" --set output.checkpoint_every=0.002 \
    --out "$work/plate4c" >/dev/null &&
    "${mpi[@]}" -np 4 "$sph" "${plate[@]}" --set output.checkpoint_every=0.002 \
      --resume "$work/plate4c" >/dev/null &&
    same_bytes "$work/plate4" "$work/plate4c"
}
check "plate np 4 resumed from a checkpoint" resumed_plate

summary
