#!/usr/bin/env bash
# ul-csph over MPI ranks (mpirun, oversubscribed on the machine's cores): the
# bar and the bending cylinder as shipped, shortened, on 2 and 4 ranks give
# the serial run's files bit for bit but the energies (check_mpi.py: the
# .pvtp series read by VTK with the serial particles and arrays, fields and
# probes identical, energies summed over ranks within 1e-12). Each reference
# update migrates the particles (the bar's moving end crosses the cut planes)
# and finds the ghosts again; their x, f0, F and stabilised force matrices
# come from their owners, so every pair sum runs in the serial order. The
# 2D path runs the punch with rollers on its symmetry planes (its mirror
# images over ranks: run_mpi_symmetry.sh); the same rank count twice writes
# the same bytes (the contact term of the rings: run_mpi_contact.sh).
# Usage: run_mpi_ul_csph.sh SPH SOURCE_DIR
set -u
sph=$1
src=$2
# shellcheck source=mpi_common.sh
. "$src/tests/mpi/mpi_common.sh"
bar=(run bar_ul_csph --quiet --set time.end=0.2 --set output.every=0.05
  --set "$fields")
cylinder=(run bending_cylinder_ul_csph --quiet --set time.end=0.03
  --set output.every=0.01 --set "$fields")
sed 's/symmetry: {axis: \([xy]\)}/roller: {axis: \1}/' \
  "$src/scenes/punch_ul_csph.yaml" >"$work/punch_rollers.yaml"
punch=(run "$work/punch_rollers.yaml" --quiet --set time.end=0.00008
  --set stability.zigzag_max=0
  --set output.every=0.00002 --set "$fields")

compare bar bar_ul_csph 1e-12 2 4 -- "${bar[@]}"
compare cylinder bending_cylinder_ul_csph 1e-12 2 4 -- "${cylinder[@]}"
compare punch punch_ul_csph 1e-12 2 4 -- "${punch[@]}"

# the bar migrates particles at its reference updates; the same rank count
# twice writes the same bytes
migrates() { grep -Eq ' [1-9][0-9]* particles migrated' "$work/bar.log"; }
"${mpi[@]}" -np 4 "$sph" "${bar[@]:0:2}" "${bar[@]:3}" --out "$work/bar.np4b" \
  >"$work/bar.log" 2>&1
check "bar np 4 migrates" migrates
check "bar np 4 twice: identical files" same_bytes "$work/bar.np4" \
  "$work/bar.np4b"
summary
