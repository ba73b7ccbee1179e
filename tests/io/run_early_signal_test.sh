#!/usr/bin/env bash
# A stop in the first moments of a run (issue 36 item 5): SIGTERM while the
# scene loads, the folder is made or the first files are written. The
# handlers are installed first, so the run either ends before writing
# anything or stops at its first step boundary with a checkpoint; either
# way the folder is then accepted: --resume finishes the run (the files of
# an uninterrupted one), or, before the first checkpoint, --resume says to
# start again with --overwrite, which does. A SIGKILL (no handler) before
# the first checkpoint leaves a folder --overwrite accepts, and --resume
# says so.
set -u
sph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
args=(--threads 1 --quiet --set 'bodies.0.particles.count=[5,25,5]'
  --set time.end=0.3 --set output.png=false)
scene=$src/scenes/twisting_column.yaml
"$sph" run "$scene" --out "$work/whole" "${args[@]}" >/dev/null || fail "uninterrupted run"

finish() { # folder, label: the stopped run's folder is accepted again
  local out=$1 what=$2 msg
  if [ -f "$out/checkpoint.sphc" ]; then
    "$sph" run "$scene" --resume "$out" "${args[@]}" >"$work/log" 2>&1 ||
      fail "$what: resume: $(cat "$work/log")"
  elif [ -d "$out" ]; then
    "$sph" run "$scene" --resume "$out" "${args[@]}" >"$work/log" 2>&1
    [ $? -eq 2 ] && grep -q -- "--overwrite" "$work/log" ||
      fail "$what: --resume without a checkpoint: $(cat "$work/log")"
    "$sph" run "$scene" --out "$out" --overwrite "${args[@]}" >"$work/log" 2>&1 ||
      fail "$what: --overwrite: $(cat "$work/log")"
  else
    "$sph" run "$scene" --out "$out" "${args[@]}" >"$work/log" 2>&1 ||
      fail "$what: plain re-run: $(cat "$work/log")"
  fi
  for f in energy.csv probes.csv twisting_column.pvd; do
    cmp -s "$work/whole/$f" "$out/$f" || fail "$what: $f differs from the uninterrupted run's"
  done
}

for delay in 0 0.01 0.03 0.05 0.08 0.12 0.2 0.3; do
  out=$work/term_$delay
  "$sph" run "$scene" --out "$out" "${args[@]}" >"$work/log" 2>&1 &
  pid=$!
  sleep "$delay"
  kill -TERM $pid 2>/dev/null
  wait $pid
  rc=$?
  case $rc in
  0) ;; # finished before the signal
  143) # killed before sph installed its handlers: then nothing was written
    grep -q "stopped by SIGTERM" "$work/log" || [ ! -e "$out" ] ||
      fail "TERM at $delay s: message '$(cat "$work/log")', folder: $(ls "$out")" ;;
  *) fail "TERM at $delay s: exit $rc: $(cat "$work/log")" ;;
  esac
  ls "$out" 2>/dev/null | grep -q '\.part$' && fail "TERM at $delay s: .part files left: $(ls "$out")"
  finish "$out" "TERM at $delay s"
done

# SIGKILL before the first checkpoint: --resume points to --overwrite
out=$work/killed
mkdir -p "$out"
"$sph" run "$scene" --out "$out" "${args[@]}" >/dev/null 2>&1 &
pid=$!
for _ in $(seq 200); do
  [ -f "$out/scene_used.yaml" ] && break
  sleep 0.005
done
kill -KILL $pid
wait $pid 2>/dev/null
rm -f "$out"/checkpoint*.sphc # as if killed before the first checkpoint
"$sph" run "$scene" --resume "$out" "${args[@]}" >"$work/log" 2>&1
[ $? -eq 2 ] && grep -q "stopped before its first one; start it again with --overwrite" "$work/log" ||
  fail "kill -9: --resume: $(cat "$work/log")"
"$sph" run "$scene" --out "$out" "${args[@]}" >"$work/log" 2>&1
[ $? -eq 2 ] && grep -q -- "--overwrite" "$work/log" || fail "kill -9: plain re-run: $(cat "$work/log")"
finish "$out" "kill -9"

echo "$fails failures"
[ $fails -eq 0 ]
