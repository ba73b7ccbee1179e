#!/usr/bin/env bash
# sph run over MPI ranks (mpirun, oversubscribed on the machine's cores):
# the twisting column with tl-csph on 2 and 4 ranks gives the serial run's
# files (check_mpi.py: fields, frames and probes identical, energies to 1e-12
# relative, the .pvtp series read by VTK with the serial particles and
# arrays); the same rank count twice writes the same bytes; --overwrite
# removes a 4-rank run's pieces; the banner notes more ranks x threads than
# cores; more ranks than useful and other commands
# than run are refused with exit 2 before anything is written. Usage:
# run_mpi_test.sh SPH SOURCE_DIR
set -u
sph=$1
src=$2
# shellcheck source=mpi_common.sh
. "$src/tests/mpi/mpi_common.sh"
run=(run twisting_column --quiet --set 'method={name: tl-csph}'
  --set time.end=0.05 --set output.every=0.01 --set output.png.width=320
  --set output.png.height=180 --set output.png.mp4=false
  --set 'output.fields=[pressure,velocity,displacement,von_mises,J,stress,body_id,particle_id]')

OMP_NUM_THREADS=1 "$sph" "${run[@]}" --out "$work/serial" >/dev/null ||
  { echo "FAIL serial run"; exit 1; }
for n in 2 4; do
  check "np $n runs" "${mpi[@]}" -np $n "$sph" "${run[@]}" --out "$work/np$n"
  check "np $n equals serial" /usr/bin/python3 "$src/tests/mpi/check_mpi.py" \
    "$work/serial" "$work/np$n" twisting_column $n 1e-12
  cat "$work/out.txt"
done

# the same rank count and thread count: the same bytes
check "np 2 again" "${mpi[@]}" -np 2 "$sph" "${run[@]}" --out "$work/np2b"
check "np 2 twice: identical files" same_bytes "$work/np2" "$work/np2b"

# --overwrite removes the pieces of a 4-rank run before a 2-rank one
check "np 2 --overwrite of np 4" "${mpi[@]}" -np 2 "$sph" "${run[@]}" \
  --out "$work/np4" --overwrite
no_stale() { ! ls "$work/np4" | grep -q '_p[23]\.vtp'; }
check "no stale pieces" no_stale

# more ranks x threads on the node than cores: the banner says so (issue 36)
cores=$(getconf _NPROCESSORS_ONLN)
banner_note() { # threads, the note's pattern, 1 if it must be there else 0
  "${mpi[@]}" -np 2 "$sph" run twisting_column --set time.end=0.005 \
    --set output.png.width=320 --set output.png.height=180 \
    --set output.png.mp4=false --threads "$1" --out "$work/note" \
    --overwrite >"$work/note.txt" 2>&1 || return 1
  grep -q "$2" "$work/note.txt"
  [ $? -eq $((1 - $3)) ] || { cat "$work/note.txt"; return 1; }
}
check "banner: 2 ranks x $cores threads oversubscribed" banner_note "$cores" \
  "^  note       2 ranks x $cores threads\? on $cores cores\?: oversubscribed" 1
[ "$cores" -ge 2 ] &&
  check "banner: 2 ranks x 1 thread, no note" banner_note 1 "^  note " 0

# refusals: exit 2 on every rank, the folder never made
expect="more than useful"
np=4 check "too many ranks refused" refused run twisting_column --quiet \
  --set 'method={name: tl-csph}' --set 'bodies.0.particles.count=[3,7,3]'
check_other() {
  "${mpi[@]}" -np 2 "$sph" check twisting_column >"$work/ref.txt" 2>&1
  [ $? -eq 2 ] && grep -q "only 'sph run' works over MPI" "$work/ref.txt"
}
check "sph check under mpirun refused" check_other

summary
