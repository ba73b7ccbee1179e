#!/usr/bin/env bash
# Every shipped scene loads, builds its particles and sets up its method;
# the scene resolved (every default filled in, as a run's scene_used.yaml
# holds it) loads again (a default of NAN was written as 'nan', which no
# scene may hold: found by the fuzz target, tests/fuzz).
set -u
sph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pass=0
fail=0
for f in "$src"/scenes/*.yaml; do
  "$sph" check "$f" >/dev/null 2>"$work/err"
  rc=$?
  if [ $rc -ne 0 ] && grep -q "built without libassimp" "$work/err"; then
    echo "skipped: $(basename "$f") (this build reads no meshes)"
  elif [ $rc -ne 0 ]; then
    fail=$((fail + 1))
    echo "FAIL: $f: $(cat "$work/err")"
  elif ! "$sph" check "$f" --resolved >"$work/used.yaml" 2>"$work/err" ||
    ! "$sph" check "$work/used.yaml" >/dev/null 2>"$work/err"; then
    fail=$((fail + 1))
    echo "FAIL: $f resolved does not load back: $(cat "$work/err")"
  else
    pass=$((pass + 1))
  fi
done
"$sph" list >/dev/null || { fail=$((fail + 1)); echo "FAIL: sph list"; }
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
