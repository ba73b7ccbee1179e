#!/usr/bin/env bash
# tools/paraview/open_run.py in ParaView's own Python (pvbatch under
# xvfb-run): it opens a run's .pvd at every time step, colours by the field
# asked for, writes a 1280 x 720 screenshot, and refuses a field the run
# lacks. Skipped (exit 77) without pvbatch and xvfb-run (Debian's paraview
# and python3-paraview conflict with python3-vtk9, which the other tests use).
set -u
sph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "from paraview import simple" >"$work/probe.py"
command -v pvbatch >/dev/null && command -v xvfb-run >/dev/null &&
  xvfb-run -a pvbatch "$work/probe.py" >/dev/null 2>&1 || {
  echo "pvbatch with ParaView's Python, or xvfb-run, not installed: skipped"
  exit 77
}
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
"$sph" run "$src/scenes/twisting_column.yaml" --out "$work/run" --quiet \
  --set output.png=false --set time.end=0.05 >/dev/null || fail "sph run"
out=$(xvfb-run -a pvbatch "$src/tools/paraview/open_run.py" "$work/run" \
  --field von_mises --screenshot "$work/shot.png" 2>&1)
echo "$out" | grep -q "11 time steps, coloured by von_mises" || fail "open_run: $out"
[ -s "$work/shot.png" ] && "$sph" imgdiff "$work/shot.png" "$work/shot.png" | grep -q "passed" ||
  fail "no screenshot"
out=$(xvfb-run -a pvbatch "$src/tools/paraview/open_run.py" "$work/run" --field density 2>&1)
echo "$out" | grep -q "no point array 'density'" || fail "missing field accepted: $out"
echo "$fails failures"
[ $fails -eq 0 ]
