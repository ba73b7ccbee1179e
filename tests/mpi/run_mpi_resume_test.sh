#!/usr/bin/env bash
# Checkpoints over MPI ranks (issue 20): every rank writes its piece, rank 0
# the manifest naming them. A 2-rank run killed mid-way (kill -9 of one
# rank), or stopped by SIGTERM to mpirun (OpenMPI passes it to every rank)
# or SIGUSR1 to one rank, resumes on 2 ranks to the .vtp/.pvtp/.pvd,
# energy.csv and probes.csv bytes of the uninterrupted 2-rank run, also from
# the older checkpoint when the newer lacks a piece; --resume on another
# rank count, without mpirun, with no complete checkpoint left, or of a
# run without MPI is refused with exit 2 and nothing changed; --overwrite
# removes the pieces. Usage:
# run_mpi_resume_test.sh SPH SOURCE_DIR
set -u
sph=$1
# shellcheck source=mpi_common.sh
. "$(dirname "$0")/mpi_common.sh"
# 3,969 particles: long enough (1.5 s and more) for mpirun to pass SIGTERM
run=(run twisting_column --quiet --set 'method={name: tl-csph}'
  --set 'bodies.0.particles.count=[9,49,9]' --set time.end=0.1 --set output.every=0.01 --set output.png=false
  --set output.checkpoint_every=0.01
  --set 'output.fields=[pressure,velocity,displacement,von_mises,J,stress,body_id,particle_id]')

# every file the uninterrupted run wrote, the same bytes
same_files() { resumed_like "$1" "$work/whole" "$2"; } # label, folder

"${mpi[@]}" -np 2 "$sph" "${run[@]}" --out "$work/whole" >/dev/null 2>&1 ||
  { echo "FAIL: uninterrupted 2-rank run"; exit 1; }
for f in checkpoint_a.sphm checkpoint_b.sphm checkpoint_a_p0.sphc checkpoint_b_p1.sphc; do
  [ -f "$work/whole/$f" ] || fail "no $f"
done
grep -q '^ranks 2$' "$work/whole/checkpoint_a.sphm" || fail "manifest: $(cat "$work/whole/checkpoint_a.sphm")"

# kill -9 of a rank once two checkpoints are in place
"${mpi[@]}" -np 2 "$sph" "${run[@]}" --out "$work/killed" >"$work/log" 2>&1 &
pid=$!
victim=$(kill_rank_when "$work/killed/checkpoint_b.sphm" $pid)
wait $pid
rc=$?
[ -n "$victim" ] || fail "kill -9: the run ended before a rank could be killed"
[ $rc -ne 0 ] || fail "kill -9: mpirun exit 0"
[ -f "$work/killed/summary.json" ] && fail "kill -9: the killed run has a summary"
cp -r "$work/killed" "$work/killed2"
"${mpi[@]}" -np 2 "$sph" "${run[@]}" --resume "$work/killed" >/dev/null 2>&1 ||
  fail "resume after kill -9"
same_files "kill -9, resumed" "$work/killed"
# the newer checkpoint without one of its pieces: the older one resumes
newest=$(grep -l "^step $(cat "$work/killed2"/checkpoint_?.sphm | sed -n 's/^step //p' |
  sort -n | tail -1)\$" "$work/killed2"/checkpoint_?.sphm)
slot=${newest%.sphm}
rm -f "${slot}_p1.sphc"
"${mpi[@]}" -np 2 "$sph" "${run[@]}" --resume "$work/killed2" \
  >"$work/log" 2>&1 || fail "resume from the older checkpoint: $(cat "$work/log")"
same_files "a piece missing, resumed from the older checkpoint" "$work/killed2"

# SIGTERM to mpirun: it passes SIGTERM to every rank (OpenMPI 4.1: after
# odls_base_sigkill_timeout, 1 s, and SIGKILL 1 s later); the ranks agree
# on a step, write a checkpoint and summary.json
stop_run() { # folder, signal, whom (mpirun or rank)
  "${mpi[@]}" -np 2 "$sph" "${run[@]}" --out "$1" >"$work/log" 2>&1 &
  local pid=$! p
  while [ ! -f "$1/twisting_column_0001.pvtp" ] && kill -0 $pid 2>/dev/null; do
    sleep 0.02
  done
  p=$pid
  [ "$3" = rank ] && p=$(rank_of $pid)
  kill -"$2" "$p"
  wait $pid
  echo $?
}
rc=$(stop_run "$work/term" TERM mpirun)
[ "$rc" -ne 0 ] || fail "SIGTERM: mpirun exit 0"
grep -q "stopped by SIGTERM" "$work/log" || fail "SIGTERM: $(cat "$work/log")"
grep -q '"stopped_by": "SIGTERM"' "$work/term/summary.json" ||
  fail "SIGTERM: summary.json has no stopped_by"
ls "$work/term" | grep -q '\.part$' && fail "SIGTERM: temporary files left"
"${mpi[@]}" -np 2 "$sph" "${run[@]}" --resume "$work/term" >/dev/null 2>&1 ||
  fail "resume after SIGTERM"
same_files "SIGTERM to mpirun, resumed" "$work/term"
# a signal reaching one rank only stops every rank (exit 128 + 10)
rc=$(stop_run "$work/usr1" USR1 rank)
[ "$rc" -eq 138 ] || fail "SIGUSR1 to a rank: exit $rc, expected 138: $(cat "$work/log")"
grep -q '"stopped_by": "SIGUSR1"' "$work/usr1/summary.json" ||
  fail "SIGUSR1: summary.json has no stopped_by"

# refusals: exit 2, the folder unchanged
refused_resume() { # label, expected message, launcher and ranks..., -- , folder
  local label=$1 expect=$2 dir=${*: -1}
  local before
  before=$(ls -l --time-style=+%s.%N "$dir" | md5sum)
  "${@:3:$#-3}" "$sph" "${run[@]}" --resume "$dir" >"$work/log" 2>&1
  local rc=$?
  [ $rc -eq 2 ] || fail "$label: exit $rc, expected 2"
  grep -q -- "$expect" "$work/log" || fail "$label: message $(cat "$work/log")"
  [ "$(ls -l --time-style=+%s.%N "$dir" | md5sum)" = "$before" ] ||
    fail "$label: files changed"
}
refused_resume "4 ranks" "written by 2 MPI ranks, this run has 4: resume with mpirun -np 2" \
  "${mpi[@]}" -np 4 "$work/usr1"
refused_resume "without mpirun" "holds one of 2 MPI ranks (checkpoint_.\.sphm): resume with mpirun -np 2" \
  env "$work/usr1"
# no complete checkpoint: a piece missing from one, the other damaged
rm -f "$work/usr1/checkpoint_a_p1.sphc"
printf '\xff' | dd of="$work/usr1/checkpoint_b_p0.sphc" bs=1 seek=300 conv=notrunc 2>/dev/null
refused_resume "no complete checkpoint" "no valid checkpoint of 2 MPI ranks to resume from (checkpoint_a.sphm: checkpoint_a_p1.sphc: cannot open.*checkpoint_b.sphm: checkpoint_b_p0.sphc: checksum mismatch" \
  "${mpi[@]}" -np 2 "$work/usr1"
# a manifest cut short: not complete
head -c 100 "$work/whole/checkpoint_a.sphm" >"$work/cut.sphm"
cp "$work/cut.sphm" "$work/usr1/checkpoint_a.sphm"
refused_resume "a manifest cut short" "checkpoint_a.sphm: incomplete or damaged" \
  "${mpi[@]}" -np 2 "$work/usr1"
# a run without MPI's checkpoint
OMP_NUM_THREADS=1 "$sph" "${run[@]}" --set time.end=0.02 --out "$work/serial" >/dev/null 2>&1 ||
  fail "serial run"
refused_resume "a serial checkpoint" "the folder holds the checkpoint of a run without MPI (checkpoint.sphc): resume it without mpirun" \
  "${mpi[@]}" -np 2 "$work/serial"

# --overwrite removes the pieces and manifests of the run before
"${mpi[@]}" -np 2 "$sph" "${run[@]}" --set time.end=0.005 --set output.every=0.005 --overwrite \
  --out "$work/usr1" >/dev/null 2>&1 || fail "--overwrite"
ls "$work/usr1" | grep -q checkpoint &&
  fail "--overwrite left $(ls "$work/usr1" | grep checkpoint | tr '\n' ' ')"

echo "$fails failures"
[ $fails -eq 0 ]
