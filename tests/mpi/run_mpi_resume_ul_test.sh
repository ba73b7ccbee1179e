#!/usr/bin/env bash
# Checkpoints over MPI ranks of the methods whose particles migrate (issue
# 20): a piece holds its rank's owned particles at that step with the cut
# tree and halo plan, and --resume on as many ranks puts them back instead
# of cutting the initial set again. On 2 ranks: the colliding rings (ul-sph)
# with the left ring driven across the cut (it migrates and re-balances
# before the stop) and the bar (ul-csph, migration at reference
# updates), each killed by kill -9 of a rank once two checkpoints are in
# place, the rings also stopped by SIGTERM to their ranks; resumed, every file
# has the bytes of the uninterrupted run's. Usage:
# run_mpi_resume_ul_test.sh SPH SOURCE_DIR
set -u
sph=$1
# shellcheck source=mpi_common.sh
. "$(dirname "$0")/mpi_common.sh"
# 1,096 particles at twice the shipped spacing; the right ring at rest
rings=(run colliding_rings --quiet --set bodies.0.particles.spacing=0.002
  --set bodies.1.particles.spacing=0.002
  --set 'bodies.0.initial_velocity.uniform=[14,0,0]'
  --set 'bodies.1.initial_velocity.uniform=[0,0,0]'
  --set time.end=0.005 --set output.every=0.001 --set output.png=false
  --set output.checkpoint_every=0.001
  --set 'output.fields=[velocity,pressure,von_mises,density,body_id,particle_id]')
bar=(run bar_ul_csph --quiet --set time.end=0.3 --set output.every=0.05
  --set output.png=false --set output.checkpoint_every=0.05 --set "$fields")

# name, scene args...: the uninterrupted run, then kill -9 of a rank and
# --resume
killed_and_resumed() {
  local name=$1 pid victim rc
  shift
  "${mpi[@]}" -np 2 "$sph" "$@" --out "$work/$name" >/dev/null 2>&1 ||
    { fail "$name: uninterrupted 2-rank run"; return; }
  grep -Eq '"migrated": [1-9]' "$work/$name/summary.json" ||
    fail "$name: no particle migrated"
  "${mpi[@]}" -np 2 "$sph" "$@" --out "$work/$name.killed" >/dev/null 2>&1 &
  pid=$!
  victim=$(kill_rank_when "$work/$name.killed/checkpoint_b.sphm" $pid)
  wait $pid
  rc=$?
  [ -n "$victim" ] || { fail "$name: the run ended before a rank was killed"; return; }
  [ $rc -ne 0 ] || fail "$name kill -9: mpirun exit 0"
  "${mpi[@]}" -np 2 "$sph" "$@" --resume "$work/$name.killed" >"$work/log" 2>&1 ||
    { fail "$name: resume after kill -9: $(tail -3 "$work/log")"; return; }
  resumed_like "$name kill -9, resumed" "$work/$name" "$work/$name.killed"
}
killed_and_resumed rings "${rings[@]}"
killed_and_resumed bar "${bar[@]}"

# SIGTERM to every rank at once (as a batch scheduler ends a job; mpirun
# passes its own on 1 s late, after a quiet machine's whole run): they stop
# at the same step with a checkpoint
"${mpi[@]}" -np 2 "$sph" "${rings[@]}" --out "$work/term" >"$work/log" 2>&1 &
pid=$!
while [ ! -f "$work/term/colliding_rings_0001.pvtp" ] && kill -0 $pid 2>/dev/null; do
  sleep 0.02
done
for r in $(pgrep -P $pid); do kill -TERM "$r"; done
wait $pid
rc=$?
[ $rc -ne 0 ] || fail "SIGTERM: mpirun exit 0"
grep -q "stopped by SIGTERM" "$work/log" || fail "SIGTERM: $(cat "$work/log")"
grep -q '"stopped_by": "SIGTERM"' "$work/term/summary.json" ||
  fail "SIGTERM: summary.json has no stopped_by"
# the checkpoint of the stop comes after migrations and re-balances
grep -Eq '"migrated": [1-9]' "$work/term/summary.json" &&
  grep -Eq '"rebalances": [1-9]' "$work/term/summary.json" ||
  fail "SIGTERM: no migration and re-balance before the stop: $(grep -E '"(migrated|rebalances)"' "$work/term/summary.json")"
grep -E '"(migrated|rebalances)"' "$work/term/summary.json" | tr -d "\n"; echo " before the stop"
"${mpi[@]}" -np 2 "$sph" "${rings[@]}" --resume "$work/term" >"$work/log" 2>&1 ||
  fail "resume after SIGTERM: $(tail -3 "$work/log")"
resumed_like "rings SIGTERM to the ranks, resumed" "$work/rings" "$work/term"

# another rank count: refused, nothing changed
before=$(ls -l --time-style=+%s.%N "$work/term" | md5sum)
"${mpi[@]}" -np 3 "$sph" "${rings[@]}" --resume "$work/term" >"$work/log" 2>&1
rc=$?
[ $rc -eq 2 ] || fail "3 ranks: exit $rc, expected 2"
grep -q "written by 2 MPI ranks, this run has 3: resume with mpirun -np 2" "$work/log" ||
  fail "3 ranks: $(cat "$work/log")"
[ "$(ls -l --time-style=+%s.%N "$work/term" | md5sum)" = "$before" ] ||
  fail "3 ranks: files changed"

echo "$fails failures"
[ $fails -eq 0 ]
