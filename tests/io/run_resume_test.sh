#!/usr/bin/env bash
# Checkpoints and resume (issue: streaming outputs): a run killed with
# SIGKILL mid-way leaves files VTK reads cleanly; --resume continues from the
# newest checkpoint and produces the same frames, CSV rows and summary
# numbers as an uninterrupted run (serial, bit-identical) for every method;
# damaged, missing and mismatched checkpoints are refused; a write failure
# (file size limit standing in for a full disk) stops the run with an error
# naming the file, keeps the rows written and leaves no temporary file
# behind, and the run resumes once the space is back.
set -u
sph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# same_run: every file and summary number of a resumed run as an
# uninterrupted one's
. "$(dirname "$0")/compare_runs.sh"
scene=$src/scenes/twisting_column.yaml
check=(/usr/bin/python3 "$(dirname "$0")/check_vtk.py")
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
bad() { fail "$@"; }

kill_and_resume() { # label, scene name, end, checkpoint interval, --set options...
  local label=$1 name=$2 end=$3 every=$4
  shift 4
  local scene=$src/scenes/$name.yaml
  local args=(--threads 1 --quiet --set time.end=$end --set output.checkpoint_every=$every "$@")
  "$sph" run "$scene" --out "$work/$label-a" "${args[@]}" >/dev/null || fail "$label: uninterrupted run"
  "$sph" run "$scene" --out "$work/$label-b" "${args[@]}" >/dev/null &
  local pid=$! waited=0
  while [ ! -f "$work/$label-b/checkpoint.prev.sphc" ] && kill -0 $pid 2>/dev/null; do
    sleep 0.02
  done
  sleep 0.05
  kill -9 $pid 2>/dev/null && waited=1
  wait $pid 2>/dev/null
  [ $waited -eq 1 ] || fail "$label: the run ended before it could be killed"
  [ -f "$work/$label-b/summary.json" ] && fail "$label: killed run has a summary"
  "${check[@]}" --series "$work/$label-b" "$name" >/dev/null ||
    fail "$label: files of the killed run do not read cleanly"
  "$sph" run "$scene" --resume "$work/$label-b" "${args[@]}" >/dev/null ||
    fail "$label: resume failed"
  echo "$label:"
  same_run "$work/$label-a" "$work/$label-b" "$name"
}

kill_and_resume tl-jst twisting_column 0.3 0.02
# tl-csph (no stabilisation) fractures at 0.175 s at the shipped 7 x 37 x 7
# (3.07 dp): resumed at 5 x 25 x 5, where it stays stable to 0.3 s
kill_and_resume tl-csph twisting_column 0.3 0.02 --set 'method={name: tl-csph}' \
  --set 'bodies.0.particles.count=[5,25,5]'
# ul-csph: the reference x^r, F^r and the steps since the update are state;
# neighbours, corrections and the stabilisation are rebuilt from them
kill_and_resume ul-csph bending_cylinder_ul_csph 0.3 0.05
# ul-sph: the configuration (neighbours, pair geometry) is rebuilt from the
# checkpoint's positions of the last update
kill_and_resume ul-sph colliding_rings 0.006 0.0005 \
  --set bodies.0.particles.spacing=0.002 --set bodies.1.particles.spacing=0.002
# a period reference: its first crossing (t ~ 0.13) is in the checkpoint
# of t = 0.2 the run resumes from
kill_and_resume period oscillating_plate_2d 0.3 0.1 \
  --set bodies.0.particles.spacing=0.004
grep -q '"period": 0\.2' "$work/period-b/summary.json" ||
  fail "period: no period measured after resume"

# damaged and mismatched checkpoints are refused, nothing is changed
d=$work/tl-jst-b
cp "$d/checkpoint.sphc" "$work/good.sphc"
printf '\xff' | dd of="$d/checkpoint.sphc" bs=1 seek=200 conv=notrunc 2>/dev/null
rm -f "$d/checkpoint.prev.sphc"
before=$(ls -l "$d" | md5sum)
out=$("$sph" run "$scene" --resume "$d" --quiet --set time.end=0.3 --set output.checkpoint_every=0.02 2>&1)
rc=$?
[ $rc -eq 2 ] || fail "damaged checkpoint: exit $rc"
echo "$out" | grep -q "checksum" || fail "damaged checkpoint: message '$out'"
[ "$(ls -l "$d" | md5sum)" = "$before" ] || fail "damaged checkpoint: files changed"
cp "$work/good.sphc" "$d/checkpoint.sphc"
out=$("$sph" run "$scene" --resume "$d" --quiet --set time.end=0.3 --set output.checkpoint_every=0.02 \
  --set 'bodies.0.particles.count=[5,25,6]' 2>&1)
rc=$?
[ $rc -eq 2 ] || fail "mismatched checkpoint: exit $rc"
echo "$out" | grep -q "particles" || fail "mismatched checkpoint: message '$out'"
out=$("$sph" run "$scene" --resume "$d" --quiet --set time.end=0.3 --set output.checkpoint_every=0.02 \
  --set materials.rubber.youngs_modulus=18e6 2>&1)
rc=$?
[ $rc -eq 2 ] || fail "other configuration: exit $rc"
echo "$out" | grep -q "different configuration" || fail "other configuration: message '$out'"
out=$("$sph" run "$scene" --resume "$work/nowhere" --quiet 2>&1)
[ $? -eq 2 ] && echo "$out" | grep -q "nothing to resume in $work/nowhere" || fail "missing folder resumed: $out"
[ ! -e "$work/nowhere" ] || fail "--resume made the missing folder"
echo "refusals: checked"

# a write failure mid-run (file size limit as a full disk): energy.csv
# outgrows 10 KiB after about 40 rows, every other file stays below (so
# coarse a column is not judged by the zig-zag indicator); the rows written
# stay, and once the space is back --resume finishes the run with the
# files of an uninterrupted one
full=$work/full
small=(--quiet --set time.end=0.3 --set output.checkpoint_every=0.02
  --set 'bodies.0.particles.count=[3,7,3]' --set output.png=false)
out=$(trap '' XFSZ; ulimit -f 10; "$sph" run "$scene" --out "$full" "${small[@]}" 2>&1)
rc=$?
[ $rc -ne 0 ] || fail "write failure: exit 0"
echo "$out" | grep -q "$full/energy.csv" || fail "write failure: message does not name the file: '$out'"
ls "$full" | grep -q '\.part$' && fail "write failure: temporary files left: $(ls "$full" | grep part)"
[ -f "$full/summary.json" ] && fail "write failure: summary.json written"
"${check[@]}" --series "$full" twisting_column >/dev/null ||
  fail "write failure: the frames written before it do not read cleanly"
rows=$(wc -l <"$full/energy.csv")
[ "$rows" -gt 30 ] || fail "write failure: energy.csv kept $rows lines"
echo "write failure: $(echo "$out" | head -1); energy.csv kept $rows lines"
"$sph" run "$scene" --out "$work/full-whole" "${small[@]}" >/dev/null || fail "uninterrupted small run"
"$sph" run "$scene" --resume "$full" "${small[@]}" >/dev/null || fail "resume after the write failure"
for f in energy.csv probes.csv twisting_column.pvd twisting_column_0060.vtp; do
  cmp -s "$work/full-whole/$f" "$full/$f" || fail "$f differs after the resume from a full disk"
done

echo "$fails failures"
[ $fails -eq 0 ]
