#!/usr/bin/env bash
# Every shipped scene loads, builds its particles and sets up its method.
set -u
sph=$1
src=$2
pass=0
fail=0
for f in "$src"/scenes/*.yaml; do
  if "$sph" check "$f" >/dev/null 2>/tmp/sph_check_err.$$; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1))
    echo "FAIL: $f: $(cat /tmp/sph_check_err.$$)"
  fi
done
rm -f /tmp/sph_check_err.$$
"$sph" list >/dev/null || { fail=$((fail + 1)); echo "FAIL: sph list"; }
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
