#!/usr/bin/env bash
# sph imgdiff from the command line: exit 0 for matching images (identical,
# shifted by one pixel), 1 for different ones (shifted by three, another
# colour map, a missing small disc, other sizes), 2 for usage errors and
# unreadable files (named on stderr); --diff writes a readable PNG and
# nothing when it cannot. Usage: run_imgdiff_tests.sh SPH MAKE_TEST_PNGS
set -u
sph=$1
make_pngs=$2
. "$(dirname "$0")/harness.sh"

"$make_pngs" "$work" || { echo "FAIL: make_test_pngs"; exit 1; }

# expect RC ARGS...: runs sph imgdiff, checks the exit status
expect() {
  local want=$1
  shift
  "$sph" imgdiff "$@" >"$work/stdout" 2>"$work/stderr"
  local rc=$?
  if [ $rc -eq "$want" ]; then
    ok
    return 0
  fi
  bad "imgdiff $* exited $rc, expected $want: $(cat "$work/stdout" "$work/stderr")"
  return 1
}

# matches and differences
expect 0 "$work/a.png" "$work/a_copy.png" &&
  { grep -q '^passed: bad_pixels=0 .*largest_cluster=0 max_channel_diff=0' "$work/stdout" && ok ||
    bad "identical: $(cat "$work/stdout")"; }
expect 0 "$work/a.png" "$work/shift1.png"
expect 1 "$work/a.png" "$work/shift3.png" &&
  { grep -q '^different' "$work/stdout" && ok || bad "shift 3: $(cat "$work/stdout")"; }
expect 0 "$work/a.png" "$work/shift3.png" --shift 3
expect 1 "$work/a.png" "$work/cool.png"
expect 0 --tolerance 255 "$work/a.png" "$work/cool.png"
expect 1 "$work/small.png" "$work/a.png" &&
  { grep -q '^different (cluster): bad_pixels=29 .*largest_cluster=29 ' "$work/stdout" && ok ||
    bad "small disc: $(cat "$work/stdout")"; }
expect 0 "$work/small.png" "$work/a.png" --max-cluster 29
expect 1 "$work/small.png" "$work/a.png" --max-cluster 29 --max-fraction 0.0001
expect 1 "$work/a.png" "$work/wide.png" &&
  { grep -qF "320x240" "$work/stderr" && grep -qF "321x240" "$work/stderr" && ok ||
    bad "sizes: $(cat "$work/stderr")"; }

# --diff: written whether or not the images match, and itself readable
expect 1 "$work/a.png" "$work/cool.png" --diff "$work/d1.png"
[ -s "$work/d1.png" ] && ok || bad "--diff on a failed comparison wrote nothing"
expect 0 "$work/a.png" "$work/a_copy.png" --diff "$work/d2.png"
[ -s "$work/d2.png" ] && ok || bad "--diff on a passed comparison wrote nothing"
expect 0 "$work/d1.png" "$work/d1.png"
expect 1 "$work/d1.png" "$work/d2.png"
expect 2 "$work/a.png" "$work/cool.png" --diff "$work/no/such/dir/d.png" &&
  { grep -qF "$work/no/such/dir/d.png" "$work/stderr" && [ ! -e "$work/no" ] && ok ||
    bad "unwritable --diff: $(cat "$work/stderr")"; }

# unreadable inputs, each named
printf 'not an image\n' >"$work/text.png"
head -c 200 "$work/a.png" >"$work/cut.png"
for f in "$work/missing.png" "$work/text.png" "$work/cut.png" "$work"; do
  expect 2 "$work/a.png" "$f" &&
    { grep -qF "sph: $f: " "$work/stderr" && ok || bad "$f not named: $(cat "$work/stderr")"; }
  expect 2 "$f" "$work/a.png"
done

# usage errors
expect 2
expect 2 "$work/a.png"
expect 2 "$work/a.png" "$work/a.png" "$work/a.png"
expect 2 "$work/a.png" "$work/a.png" --frobnicate
expect 2 "$work/a.png" "$work/a.png" --tolerance
expect 2 "$work/a.png" "$work/a.png" --tolerance abc
expect 2 "$work/a.png" "$work/a.png" --tolerance 256
expect 2 "$work/a.png" "$work/a.png" --shift -1
expect 2 "$work/a.png" "$work/a.png" --shift 9
expect 2 "$work/a.png" "$work/a.png" --max-fraction 1.5
expect 2 "$work/a.png" "$work/a.png" --max-fraction nan
expect 2 "$work/a.png" "$work/a.png" --max-cluster -3
expect 2 "$work/a.png" "$work/a.png" --diff
"$sph" help | grep -q 'imgdiff A.png B.png' && ok || bad "imgdiff missing from sph help"

echo "imgdiff cli: $pass passed, $fail failed"
[ $fail -eq 0 ]
