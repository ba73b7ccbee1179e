#!/usr/bin/env bash
# Fault injection (label fault): a disk that fills up at each output kind.
# For a small twisting column (3 x 7 x 3 particles, 0.3 s, 61 outputs) the
# output folder (for the frames: its frames/ folder) is a tmpfs too small
# for the run; the run stops with exit 3 and an error naming the file that
# did not fit, keeps every frame and CSV row written (kept_run:
# compare_runs.sh), and once the space is back (a filler file removed) --resume
# finishes with the files of an uninterrupted run (same_run). The tmpfs is
# mounted in a mount namespace of its own (unshare: as root, else in a user
# namespace); where neither is allowed the test is skipped (exit 77). Each
# output kind is the one that fills the disk in some of the sizes tried:
# the CSV tables, the .vtp/.pvd files, the checkpoint, the PNG frames.
set -u
sph=$1
src=$2
. "$src/tests/cli/harness.sh"
. "$(dirname "$0")/compare_runs.sh" # scene, small: the run

ns=(unshare --mount --propagation private)
[ "$(id -u)" -eq 0 ] || ns=(unshare --user --map-root-user --mount --propagation private)
mkdir -p "$work/probe"
if ! "${ns[@]}" mount -t tmpfs -o size=64k tmpfs "$work/probe" 2>"$work/err"; then
  why="cannot mount a tmpfs here (needs root or user namespaces): $(cat "$work/err")"
  # CI (.ci/run, as root) sets SPH_FAULT_REQUIRE_TMPFS=1: there a skip fails
  [ "${SPH_FAULT_REQUIRE_TMPFS:-0}" = 1 ] && { echo "FAIL: $why"; exit 1; }
  echo "SKIP: $why"
  exit 77
fi

# in the namespace: a tmpfs at BASE with SIZE kB free (4 MB more, taken by
# a filler file: a user namespace may not grow a tmpfs), the run into OUT
# (BASE/out, or any folder with BASE/frames bound as its frames/), a copy
# of what it left in SNAP, the space back (the filler removed), --resume,
# the result copied to DONE (the tmpfs goes with the namespace)
full_then_resume() { # base size where out snap done -- sph run args...
  local base=$1 size=$2 where=$3 out=$4 snap=$5 done=$6
  shift 6
  mkdir -p "$base" && mount -t tmpfs -o "size=$((size + 4096))k" tmpfs "$base" || return 90
  if [ "$where" = frames ]; then
    mkdir -p "$base/frames" "$out/frames" && mount --bind "$base/frames" "$out/frames" || return 91
  fi
  fallocate -l 4M "$base/filler" 2>/dev/null || head -c 4194304 /dev/zero >"$base/filler" || return 92
  "$@" --out "$out" >"$snap.log" 2>&1
  echo "exit $?" >>"$snap.log"
  cp -a "$out" "$snap"
  rm "$base/filler"
  "$@" --resume "$out" >"$done.log" 2>&1
  echo "exit $?" >>"$done.log"
  cp -a "$out" "$done"
}

# fill KIND WHERE REGEX SWEEP -- --set options: the uninterrupted run in
# $work/KIND-ref; then tmpfs sizes of SWEEP per cent of what the run wrote
# under WHERE (out or frames), until the error names a file matching REGEX
fill() {
  local kind=$1 where=$2 regex=$3 sweep=$4
  shift 5
  local args=("${small[@]}" "$@") ref=$work/$kind-ref
  "$sph" run $scene --out "$ref" "${args[@]}" >"$work/$kind-ref.log" 2>&1 ||
    { bad "$kind: uninterrupted run (exit $?): $(cat "$work/$kind-ref.log")"; return; }
  local used
  used=$(du -sk "$ref/$([ "$where" = frames ] && echo frames)" | cut -f1)
  local pct hit=""
  for pct in $sweep; do
    local size=$(((used * pct / 100 + 3) / 4 * 4)) t=$work/$kind-$pct
    local out=$t/fs/out
    [ "$where" = frames ] && out=$t/out
    "${ns[@]}" bash -c "$(declare -f full_then_resume); full_then_resume \"\$@\"" _ \
      "$t/fs" "$size" "$where" "$out" "$t/snap" "$t/done" "$sph" run $scene "${args[@]}"
    local rc=$?
    [ $rc -eq 0 ] || { bad "$kind $size kB: no tmpfs (exit $rc)"; continue; }
    local msg
    msg=$(grep '^sph: ' "$t/snap.log" | head -1)
    if ! grep -q '^exit 3$' "$t/snap.log" || ! echo "$msg" | grep -q "^sph: $out/.*: No space left on device"; then
      bad "$kind $size kB: $(cat "$t/snap.log")"
      continue
    fi
    local file=${msg#"sph: $out/"}
    file=${file%%:*}
    echo "$kind, tmpfs $size kB ($pct % of $used kB): $file full"
    [ ! -f "$t/snap/summary.json" ] || bad "$kind $size kB: summary.json written"
    kept_run "$t/snap" "$ref" $scene
    grep -q '^exit 0$' "$t/done.log" || { bad "$kind $size kB: resume: $(cat "$t/done.log")"; continue; }
    same_run "$ref" "$t/done" $scene
    if echo "$file" | grep -qE "$regex"; then
      hit=$file
      break
    fi
  done
  [ -n "$hit" ] && ok || bad "$kind: no size tried filled the disk at a $kind file"
}

fill csv out '^(energy|probes)\.csv$' "45 55 65 75 85" -- --set output.png=false \
  --set output.vtk=false --set output.checkpoint_every=0.05
fill vtk out '\.(vtp|pvd)$' "45 55 65 75 85" -- --set output.png=false \
  --set output.checkpoint_every=0.1
fill checkpoint out '^checkpoint\.sphc$' "45 55 65 75 85" -- --set output.png=false \
  --set output.vtk=false --set output.checkpoint_every=0.005
fill png frames '^frames/.*\.png$' "45 65 85" -- --set output.png.width=160 \
  --set output.png.height=120 --set output.png.mp4=false --set output.checkpoint_every=0.1

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
