#!/usr/bin/env bash
# SIGTERM and SIGINT mid-run (issue 17, issue 21 item 12): the run stops at
# the next step boundary with exit 143 / 130, every file in place (no
# .part), a .pvd series VTK reads, summary.json with completed false and
# stopped_by, and a checkpoint from which --resume finishes the run with the
# energy.csv, probes.csv and .vtp files of an uninterrupted one.
set -u
sph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
check=(/usr/bin/python3 "$(dirname "$0")/check_vtk.py")
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
args=(--threads 1 --quiet --set 'bodies.0.particles.count=[5,25,5]'
  --set time.end=1.5 --set output.png=false)
scene=$src/scenes/twisting_column.yaml

"$sph" run "$scene" --out "$work/whole" "${args[@]}" >/dev/null || fail "uninterrupted run"

stop_with() { # signal, expected exit, folder
  local sig=$1 want=$2 out=$3
  "$sph" run "$scene" --out "$out" "${args[@]}" >"$work/log" 2>&1 &
  local pid=$!
  for _ in $(seq 300); do # until the run has written 20 frames
    [ -f "$out/twisting_column_0020.vtp" ] && break
    sleep 0.02
  done
  kill -"$sig" $pid
  wait $pid
  local rc=$?
  [ $rc -eq "$want" ] || fail "$sig: exit $rc, expected $want: $(cat "$work/log")"
  grep -q "stopped by SIG$sig at t = " "$work/log" || fail "$sig: message '$(cat "$work/log")'"
  ls "$out" | grep -q '\.part$' && fail "$sig: temporary files left: $(ls "$out" | grep part)"
  /usr/bin/python3 - "$out/summary.json" "SIG$sig" <<'PY' || fail "$sig: summary.json"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["completed"] is False and s["stopped_by"] == sys.argv[2], s
assert 0 < s["t_reached"] < 1.5, s
PY
  [ -f "$out/checkpoint.sphc" ] || fail "$sig: no checkpoint"
  "${check[@]}" --series "$out" twisting_column >/dev/null || fail "$sig: the series does not read cleanly"
}

stop_with TERM 143 "$work/term"
stop_with INT 130 "$work/int"
# the stopped run resumes to the uninterrupted one's files
"$sph" run "$scene" --resume "$work/term" "${args[@]}" >/dev/null || fail "resume after SIGTERM"
for f in energy.csv probes.csv twisting_column.pvd twisting_column_0300.vtp twisting_column_0150.vtp; do
  cmp -s "$work/whole/$f" "$work/term/$f" || fail "$f differs after the resume"
done
grep -q '"completed": true' "$work/term/summary.json" || fail "resumed run not completed"
# how often each part ran is in the checkpoint (issue 21)
[ "$(grep '"calls"' "$work/whole/summary.json")" = "$(grep '"calls"' "$work/term/summary.json")" ] ||
  fail "summary.json calls differ after the resume: $(grep -h '"calls"' "$work/whole/summary.json" "$work/term/summary.json")"

# frames: the follow camera and the colour range continue across a stop
# and a resume (replayed from the .vtp files), so every frame equals the
# uninterrupted run's (issue 21 item 8)
rargs=(--threads 1 --quiet --set bodies.0.particles.spacing=0.002
  --set bodies.1.particles.spacing=0.002 --set time.end=0.025
  --set output.png.width=320 --set output.png.height=240 --set output.png.mp4=false
  --set output.png.range=auto)
"$sph" run colliding_rings --out "$work/ra" "${rargs[@]}" >/dev/null || fail "rings run"
"$sph" run colliding_rings --out "$work/rb" "${rargs[@]}" >/dev/null &
pid=$!
for _ in $(seq 500); do
  [ -f "$work/rb/colliding_rings_0035.vtp" ] && break
  sleep 0.01
done
kill -TERM $pid
wait $pid
"$sph" run colliding_rings --resume "$work/rb" "${rargs[@]}" >/dev/null || fail "rings resume"
same=0
for f in "$work"/ra/frames/*.png; do
  cmp -s "$f" "$work/rb/frames/$(basename "$f")" && same=$((same + 1))
done
[ $same -eq 51 ] || fail "frames after the resume: $same of 51 identical"

# the checkpoint files too: a stop's checkpoint between two of the cadence's
# is replaced by the resumed run's next one, so the resumed run ends with
# the uninterrupted one's checkpoint.sphc and checkpoint.prev.sphc (issue
# 36 item 8)
# (cadence 0.5 s: checkpoints at 0.5 and 1 s, the stop between them)
cargs=("${args[@]}" --set output.checkpoint_every=0.5)
"$sph" run "$scene" --out "$work/cwhole" "${cargs[@]}" >/dev/null || fail "checkpointed run"
"$sph" run "$scene" --out "$work/cterm" "${cargs[@]}" >/dev/null 2>&1 &
pid=$!
for _ in $(seq 300); do
  [ -f "$work/cterm/twisting_column_0150.vtp" ] && break
  sleep 0.02
done
kill -TERM $pid
wait $pid
grep -q '"t_reached": 0\.[5-9]' "$work/cterm/summary.json" ||
  fail "the stop is not between the checkpoints: $(grep t_reached "$work/cterm/summary.json")"
"$sph" run "$scene" --resume "$work/cterm" "${cargs[@]}" >/dev/null || fail "checkpointed resume"
for f in checkpoint.sphc checkpoint.prev.sphc energy.csv; do
  cmp -s "$work/cwhole/$f" "$work/cterm/$f" || fail "$f differs after the resume"
done

echo "$fails failures"
[ $fails -eq 0 ]
