#!/usr/bin/env bash
# The scene loader's fuzz findings and the inputs of issue 21, replayed
# through `sph check` in the normal build (ctest -R fuzz_regressions): each
# file of tests/fuzz/regressions/ is a scene, optionally followed by a NUL
# and --set overrides each ended by a NUL (the fuzz target's input,
# tests/fuzz/fuzz_scene.c). Each must be accepted or refused (exit 0 or 2),
# never crash, run out of memory or hang (60 s), with the fuzz target's
# memory limit (--max-memory 16M); an accepted one's resolved scene
# (--resolved, a run's scene_used.yaml) must be accepted again.
set -u
sph=$1
src=$2
. "$src/tests/cli/harness.sh"
n=0
for f in "$src"/tests/fuzz/regressions/*; do
  [ -f "$f" ] || continue
  n=$((n + 1))
  name=$(basename "$f")
  sets=()
  first=1
  : >"$work/scene.yaml"
  while IFS= read -r -d '' piece || [ -n "$piece" ]; do
    if [ $first = 1 ]; then
      printf '%s' "$piece" >"$work/scene.yaml"
      first=0
    else
      sets+=("--set=$piece")
    fi
  done <"$f"
  timeout 60 "$sph" check "$work/scene.yaml" --max-memory 16M "${sets[@]}" >"$work/out" 2>&1
  rc=$?
  if [ $rc -ne 0 ] && [ $rc -ne 2 ]; then
    bad "$name: exit $rc (${#sets[@]} overrides): $(tail -3 "$work/out")"
    continue
  fi
  if [ $rc -eq 0 ]; then
    "$sph" check "$work/scene.yaml" --max-memory 16M "${sets[@]}" --resolved >"$work/used.yaml" 2>"$work/out" &&
      timeout 60 "$sph" check "$work/used.yaml" --max-memory 16M >"$work/out" 2>&1
    rc=$?
    [ $rc -eq 0 ] || { bad "$name: the resolved scene does not load again (exit $rc): $(tail -3 "$work/out")"; continue; }
  fi
  ok
done
[ $n -gt 0 ] || bad "no regression inputs in $src/tests/fuzz/regressions"
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
