#!/usr/bin/env bash
# tl-jst over MPI ranks (mpirun, oversubscribed on the machine's cores): the
# twisting column and the punch as shipped, shortened, on 2 and 4 ranks give
# the serial run's files to round-off (check_mpi.py --roundoff: the .pvtp
# series read by VTK with the serial particles and arrays, fields, probes,
# energies and momenta within 1e-12 relative; frames alike by sph imgdiff).
# The bound: the projections' global sums, added in rank order, differ from
# the serial order by about 1e-16 relative per step; the smooth motion lets
# that grow about linearly (measured: 4e-14 after the column's 290 steps,
# 8e-14 after the punch's 534), so 1e-12 leaves a factor 10 and more, while a
# ghost value from the wrong state or a missing exchange gives 1e-4 and more.
# The symmetric force (its ghosts' P exchanged) and eq31 (its ghosts' kernel
# gradients from their owners' coefficients) likewise; the same rank count
# twice writes the same bytes. essential_bc lagrange (seed 000 App. B: the
# multiplier system's sums over the particles added in rank order, solved on
# every rank) likewise to 1e-12 (measured 4.1e-14 on 2 ranks, 4.6e-14 on 4
# after the column's 109 steps).
# tl-bond (its ghosts' pair weights from their owners' coefficients, no
# global sum) gives the serial files bit for bit but the energies (check_mpi.py
# without --roundoff, as tl-csph), with the first- and the zeroth-order
# correction (the ghosts' L grad W~0 from their owners' S, gamma and L).
# Usage: run_mpi_tl_jst.sh SPH SOURCE_DIR
set -u
sph=$1
src=$2
# shellcheck source=mpi_common.sh
. "$src/tests/mpi/mpi_common.sh"
column=(run twisting_column --quiet --set time.end=0.05 --set output.every=0.01
  --set output.png.width=320 --set output.png.height=180
  --set output.png.mp4=false --set "$fields")
punch=(run punch --quiet --set time.end=0.005 --set output.every=0.001
  --set "$fields")
symmetric=("${column[@]}" --set method.force=symmetric --set time.end=0.02)
bond=(run twisting_column_bond --quiet --set time.end=0.005
  --set output.every=0.0025 --set output.png.width=320
  --set output.png.height=180 --set output.png.mp4=false --set "$fields")
roundoff="1e-12 --roundoff"
compare column twisting_column "$roundoff" 2 4 -- "${column[@]}"
compare punch punch "$roundoff" 2 4 -- "${punch[@]}"
compare symmetric twisting_column "$roundoff" 2 -- "${symmetric[@]}"
compare eq31 punch "$roundoff" 2 -- "${punch[@]}" --set method.force=eq31 \
  --set time.end=0.003
compare bond twisting_column_bond 1e-12 2 -- "${bond[@]}"
compare bond0 twisting_column_bond 1e-12 2 3 -- "${bond[@]}" \
  --set method.correction=zeroth_order
compare lagrange twisting_column "$roundoff" 2 4 -- "${column[@]}" \
  --set time.end=0.02 --set method.essential_bc=lagrange

# the same rank count and thread count: the same bytes
check "punch np 2 again" "${mpi[@]}" -np 2 "$sph" "${punch[@]}" \
  --out "$work/punch.np2b"
check "punch np 2 twice: identical files" same_bytes "$work/punch.np2" \
  "$work/punch.np2b"

summary
