#!/usr/bin/env bash
# A rank dying mid-run (issue 20): kill -9 of one rank of a 2-rank run,
# at three moments, makes mpirun end the others and exit non-zero with
# OpenMPI's message naming the rank and the signal; every file under its
# final name is whole (check_killed.py: the .pvd, .pvtp and pieces read in
# VTK, PNG frames complete, checkpoint manifests and the pieces they name
# intact; what was being written is under its .part name), no summary.json,
# and --resume finishes the run. Usage: run_mpi_kill_test.sh SPH SOURCE_DIR
set -u
sph=$1
src=$2
# shellcheck source=mpi_common.sh
. "$(dirname "$0")/mpi_common.sh"
# a frame (2 .vtp pieces, a .pvtp, the .pvd, a PNG) every 5 to 6 steps and
# a checkpoint every 0.005 s: a kill often lands in a write
run=(run twisting_column --quiet --set 'method={name: tl-csph}'
  --set 'bodies.0.particles.count=[9,49,9]' --set time.end=0.06
  --set output.every=0.001 --set output.checkpoint_every=0.005
  --set output.png.width=320 --set output.png.height=180
  --set output.png.mp4=false
  --set 'output.fields=[pressure,velocity,stress,particle_id]')

for k in 1 2 3; do
  out=$work/k$k
  "${mpi[@]}" -np 2 "$sph" "${run[@]}" --out "$out" >"$work/log" 2>&1 &
  pid=$!
  while [ ! -f "$out/twisting_column_0010.pvtp" ] && kill -0 $pid 2>/dev/null; do
    sleep 0.01
  done
  sleep "0.$((k * 3))$k"
  victim=$(pgrep -P $pid | tail -1)
  [ -n "$victim" ] && kill -9 "$victim"
  wait $pid
  rc=$?
  if [ -z "$victim" ] || [ -f "$out/summary.json" ] && [ $rc -eq 0 ]; then
    fail "kill $k: the run ended before a rank could be killed"
    continue
  fi
  [ $rc -ne 0 ] || fail "kill $k: mpirun exit 0"
  grep -q "exited on signal 9" "$work/log" || fail "kill $k: message '$(cat "$work/log")'"
  echo "kill $k: exit $rc; $(grep -o "process rank [0-9]* .*exited on signal 9 (Killed)" "$work/log")"
  /usr/bin/python3 "$src/tests/mpi/check_killed.py" "$out" twisting_column 2 3969 ||
    fail "kill $k: files under final names are not whole"
done
"${mpi[@]}" -np 2 "$sph" "${run[@]}" --resume "$work/k3" >"$work/log" 2>&1 ||
  fail "resume after kill -9: $(cat "$work/log")"
grep -q '"completed": true' "$work/k3/summary.json" || fail "resumed run not completed"
ls "$work/k3" "$work/k3/frames" | grep -q '\.part$' && fail "resume left .part files"

echo "$fails failures"
[ $fails -eq 0 ]
