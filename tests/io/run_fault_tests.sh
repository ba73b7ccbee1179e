#!/usr/bin/env bash
# Fault injection (label fault) besides a full disk (run_fault_disk_full.sh):
# a file-size limit (SIGXFSZ, not trapped), SIGTERM mid-run, a second run
# into the busy output folder, kill -9 while a checkpoint is written and
# kill -9 as a resume starts. Each on a small twisting column; each asserts
# that nothing written is lost (kept_run: frames identical to the
# uninterrupted run's, CSV tables its byte prefix, no .part, the series
# reads) and that --resume then finishes with the uninterrupted run's
# files (same_run). io_resume and io_signals (labels io and fault) kill -9
# every method and stop with SIGINT too.
set -u
sph=$1
src=$2
. "$src/tests/cli/harness.sh"
. "$(dirname "$0")/compare_runs.sh" # scene, small: the run

reference() { # dir, run args...
  local d=$1
  shift
  "$sph" run $scene --out "$d" "$@" >/dev/null || bad "uninterrupted run into $d"
}
resume_same() { # reference, stopped dir, run args...
  local r=$1 d=$2
  shift 2
  "$sph" run $scene --resume "$d" "$@" >"$work/log" 2>&1 || { bad "resume $d: $(cat "$work/log")"; return; }
  same_run "$r" "$d" $scene
}

# a file-size limit, SIGXFSZ not trapped by the shell: sph ignores it and
# stops at the file that outgrew the limit (energy.csv outgrows 10 kB after
# about 50 rows, the checkpoints and probes.csv stay below), exit 3
echo "file-size limit:"
csv=("${small[@]}" --set output.png=false --set output.vtk=false --set output.checkpoint_every=0.05)
reference "$work/csv-ref" "${csv[@]}"
(
  ulimit -f 10
  exec "$sph" run $scene --out "$work/fsize" "${csv[@]}" >"$work/log" 2>&1
)
rc=$?
[ $rc -eq 3 ] && grep -q "^sph: $work/fsize/energy.csv: cannot write the file: File too large" "$work/log" &&
  ok || bad "file-size limit: exit $rc: $(cat "$work/log")"
kept_run "$work/fsize" "$work/csv-ref" $scene
resume_same "$work/csv-ref" "$work/fsize" "${csv[@]}"

# SIGTERM mid-run with every output (frames, .vtp, CSV, checkpoints)
echo "SIGTERM:"
all=("${small[@]}" --set output.png.width=160 --set output.png.height=120
  --set output.png.mp4=false --set output.checkpoint_every=0.05)
reference "$work/all-ref" "${all[@]}"
"$sph" run $scene --out "$work/term" "${all[@]}" >"$work/log" 2>&1 &
pid=$!
until [ -f "$work/term/frames/${scene}_0015.png" ] || ! kill -0 $pid 2>/dev/null; do sleep 0.01; done
kill -TERM $pid
wait $pid
rc=$?
[ $rc -eq 143 ] && grep -q "stopped by SIGTERM" "$work/log" && ok || bad "SIGTERM: exit $rc: $(cat "$work/log")"
grep -q '"stopped_by": "SIGTERM"' "$work/term/summary.json" || bad "SIGTERM: summary.json"
kept_run "$work/term" "$work/all-ref" $scene
resume_same "$work/all-ref" "$work/term" "${all[@]}"

# a second run into a busy folder (plain, --overwrite, --resume) is
# refused naming the first one's pid and changes nothing: the first
# (held with SIGSTOP meanwhile) finishes with the files of an undisturbed
# run
echo "concurrent --out:"
"$sph" run $scene --out "$work/busy" "${all[@]}" >/dev/null 2>&1 &
pid=$!
until [ -f "$work/busy/frames/${scene}_0010.png" ] || ! kill -0 $pid 2>/dev/null; do sleep 0.01; done
kill -STOP $pid
for extra in "" --overwrite --resume; do
  if [ "$extra" = --resume ]; then
    "$sph" run $scene --resume "$work/busy" "${all[@]}" >/dev/null 2>"$work/log"
  else
    "$sph" run $scene --out "$work/busy" $extra "${all[@]}" >/dev/null 2>"$work/log"
  fi
  rc=$?
  [ $rc -eq 2 ] && grep -qF "$work/busy is in use by another sph run (pid $pid)" "$work/log" && ok ||
    bad "second run ${extra:-plain}: exit $rc: $(cat "$work/log")"
done
kill -CONT $pid
wait $pid || bad "the first run failed beside the refused ones"
same_run "$work/all-ref" "$work/busy" $scene

# kill -9 while checkpoint.sphc.part is being written (1,813 particles,
# a checkpoint at every output: about 0.3 MB each): the checkpoints before
# it stay and --resume finishes the run
echo "kill -9 during a checkpoint write:"
big=(--threads 1 --quiet --set time.end=0.05 --set output.png=false --set output.vtk=false
  --set output.checkpoint_every=0.005)
reference "$work/big-ref" "${big[@]}"
hit=0
for try in 1 2 3 4 5 6; do
  d=$work/ck$try
  "$sph" run $scene --out "$d" "${big[@]}" >/dev/null 2>&1 &
  pid=$!
  # the first checkpoints pass; then kill at the moment a .part appears
  until [ -f "$d/checkpoint.prev.sphc" ] || ! kill -0 $pid 2>/dev/null; do sleep 0.005; done
  until [ -e "$d/checkpoint.sphc.part" ] || ! kill -0 $pid 2>/dev/null; do :; done
  kill -9 $pid 2>/dev/null
  wait $pid 2>/dev/null
  [ -e "$d/checkpoint.sphc.part" ] || continue # finished writing it first
  hit=1
  echo "  killed in a checkpoint write (try $try): $(ls "$d" | grep sphc | tr '\n' ' ')"
  parts_ok=1 kept_run "$d" "$work/big-ref" $scene
  resume_same "$work/big-ref" "$d" "${big[@]}"
  [ ! -e "$d/checkpoint.sphc.part" ] || bad "the resumed run left checkpoint.sphc.part"
  break
done
[ $hit -eq 1 ] && ok || bad "no kill landed during a checkpoint write in 6 tries"

# kill -9 as a resume starts (625 particles, so that 0.05 s between
# outputs take about 0.2 s): once it has written its scene_used.yaml (a
# new file: a new inode) the CSV tables are opened; killed then and a few
# moments after, the rows the checkpoint counts stay (a resume used to
# rewrite the tables from memory, losing every row until its first
# flush), and the next resume finishes the run
echo "kill -9 as a resume starts:"
slow=(--threads 1 --quiet --set 'bodies.0.particles.count=[5,25,5]' --set time.end=0.3
  --set output.png=false --set output.vtk=false --set output.every=0.05
  --set output.checkpoint_every=0.05)
reference "$work/slow-ref" "${slow[@]}"
"$sph" run $scene --out "$work/rk" "${slow[@]}" >/dev/null 2>&1 &
pid=$!
until [ -f "$work/rk/checkpoint.prev.sphc" ] || ! kill -0 $pid 2>/dev/null; do sleep 0.005; done
kill -9 $pid 2>/dev/null
wait $pid 2>/dev/null
for delay in 0 0.002 0.005 0.01 0.02 0.04; do
  inode=$(stat -c %i "$work/rk/scene_used.yaml")
  "$sph" run $scene --resume "$work/rk" "${slow[@]}" >/dev/null 2>&1 &
  pid=$!
  while [ "$(stat -c %i "$work/rk/scene_used.yaml" 2>/dev/null)" = "$inode" ] &&
    kill -0 $pid 2>/dev/null; do :; done
  sleep $delay
  kill -9 $pid 2>/dev/null
  wait $pid 2>/dev/null
  lines=$(wc -l <"$work/rk/energy.csv")
  [ "$lines" -ge 3 ] || bad "killed $delay s after a resume wrote scene_used.yaml: energy.csv has $lines lines"
  parts_ok=1 kept_run "$work/rk" "$work/slow-ref" $scene >/dev/null
done
resume_same "$work/slow-ref" "$work/rk" "${slow[@]}"

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
