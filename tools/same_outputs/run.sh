#!/usr/bin/env bash
# run.sh SPH OUTROOT [MODE]: every shipped scene's CI-sized variant (about 60
# steps, 4 outputs, 320x180 PNG frames), written to OUTROOT/<scene>.
# MODE: t1 (1 thread), t2 (2 threads), r2 (2 MPI ranks, 1 thread each).
# A change that must change no number runs this with the old and the new
# binary and compares the two folders: compare.py OLD NEW (docs/develop.md).
sph=$(readlink -f "$1"); root=$2; mode=${3:-t1}
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$root"
for f in "$src"/scenes/*.yaml; do
  n=$(basename "$f" .yaml)
  dt=$("$sph" check "$f" 2>/dev/null | sed -n 's/.*first dt \([0-9.e+-]*\) s.*/\1/p' | head -1)
  tend=$("$sph" check "$f" 2>/dev/null | sed -n 's/.*time *end \([0-9.e+-]*\) s.*/\1/p' | head -1)
  end=$(python3 -c "print('%.6g' % min($tend, 60*$dt))")
  every=$(python3 -c "print('%.6g' % ($end/4))")
  sets=(--set time.end=$end --set output.every=$every --set 'output.png={width: 320, height: 180, mp4: false}')
  case $mode in
    t1) OMP_NUM_THREADS=1 "$sph" run "$f" --threads 1 --out "$root/$n" --overwrite --quiet "${sets[@]}" >"$root/$n.log" 2>&1 ;;
    t2) "$sph" run "$f" --threads 2 --out "$root/$n" --overwrite --quiet "${sets[@]}" >"$root/$n.log" 2>&1 ;;
    r2) mpirun --oversubscribe --allow-run-as-root -np 2 --mca mpi_yield_when_idle 1 "$sph" run "$f" --threads 1 --out "$root/$n" --overwrite --quiet "${sets[@]}" >"$root/$n.log" 2>&1 ;;
  esac
  echo "$n rc=$? end=$end"
done
