#!/usr/bin/env bash
# The contact term over MPI ranks (mpirun, oversubscribed on the machine's
# cores): the rubber rings with ul-csph, shortened to 0.01 s (contact from
# 0.0085 s), on 2 and 3 ranks give the serial run's files (check_mpi.py:
# fields, frames and probes identical, energies to 1e-12): both rings
# (contact between bodies across the rank cut, through the ghosts of the
# dynamic domain) and one ring on its wall (ul-csph, and tl-csph on 2
# ranks). The rings with tl-csph (ghosts fixed in the reference
# configuration: the particles near the other ring come from their owners
# at every stage) on 2 and 3 ranks give the serial files too, and with
# tl-jst on 2 to round-off: its projections sum over the ranks in rank
# order and the contact springs amplify that (probes 5.4e-11, fields
# 1.7e-13 of their largest at 0.01 s, measured; bound 1e-10). A ghost
# layer outrun between reference updates stops the run with a message.
# Usage: run_mpi_contact.sh SPH SOURCE_DIR
set -u
sph=$1
src=$2
# shellcheck source=mpi_common.sh
. "$src/tests/mpi/mpi_common.sh"
# a rank waiting yields its core (2 cores shared by 3 ranks)
mpi+=(--mca mpi_yield_when_idle 1)
short=(--quiet --set time.end=0.01 --set output.every=0.0025
  --set 'output.png={width: 320, height: 180, mp4: false}' --set "$fields")

compare rings rubber_rings_ul_csph 1e-12 2 3 -- \
  run rubber_rings_ul_csph "${short[@]}"
compare rings_tl rubber_rings_ul_csph 1e-12 2 3 -- \
  run rubber_rings_ul_csph "${short[@]}" --set 'method={name: tl-csph}'
compare rings_jst rubber_rings_ul_csph "1e-10 --roundoff" 2 -- \
  run rubber_rings_ul_csph "${short[@]}" --set 'method={name: tl-jst}'
compare wall rubber_ring_symmetry 1e-12 2 3 -- \
  run rubber_ring_symmetry "${short[@]}"
compare wall_tl rubber_ring_symmetry 1e-12 2 -- \
  run rubber_ring_symmetry "${short[@]}" --set 'method={name: tl-csph}'

# no reference update for the whole run: the ghosts found at the start stop
# covering the contact radius (0.8 spacings moved at 0.0027 s)
outrun() {
  "${mpi[@]}" -np 2 "$sph" run rubber_rings_ul_csph --quiet \
    --set method.update_every=100000 --set time.end=0.004 \
    --set output.png=false --out "$work/outrun" >"$work/outrun.txt" 2>&1
  local rc=$?
  [ $rc -eq 1 ] && grep -q "since the ghosts were found" "$work/outrun.txt"
}
check "ghost layer outrun stops the run" outrun
summary
