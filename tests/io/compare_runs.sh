# Shared by the resume and fault tests (sourced; needs a `bad MESSAGE`
# function): what a stopped run kept, and a finished run against an
# uninterrupted one.

# the fault tests' run: a twisting column of 3 x 7 x 3 particles to 0.3 s
# (61 outputs, about 600 steps, well under a second)
scene=twisting_column
small=(--threads 1 --quiet --set 'bodies.0.particles.count=[3,7,3]' --set time.end=0.3)

# kept_run STOPPED REFERENCE NAME: what a run stopped by a failure or a
# signal left: no temporary (.part) file (parts_ok=1: a run killed with
# SIGKILL may leave them), every .vtp identical to the uninterrupted run's
# and every PNG frame a whole image (their colour range and camera are
# the stopped run's own, one for all its frames; after --resume they equal
# the uninterrupted run's, same_run), each CSV table a byte prefix of the uninterrupted
# one (rows kept, at most a torn last line), the .pvd series read cleanly
# by VTK's reader. Prints the rows kept.
kept_run() {
  local s=$1 r=$2 name=$3 f
  local parts
  parts=$(find "$s" -name '*.part')
  [ -z "$parts" ] || [ "${parts_ok:-0}" = 1 ] || bad "$s: temporary files left: $parts"
  for f in "$s"/*.vtp; do
    [ -e "$f" ] || continue
    cmp -s "$f" "$r/${f#"$s"/}" || bad "$s: ${f#"$s"/} differs from the uninterrupted run's"
  done
  for f in "$s"/frames/*.png; do
    [ -e "$f" ] || continue
    [ -e "$r/${f#"$s"/}" ] || bad "$s: ${f#"$s"/} is not a frame of the uninterrupted run"
    "${sph:?}" imgdiff "$f" "$f" >/dev/null 2>&1 || bad "$s: ${f#"$s"/} is not a whole PNG"
  done
  for f in energy.csv probes.csv; do
    [ -f "$r/$f" ] || continue
    [ -f "$s/$f" ] || { bad "$s: $f lost"; continue; }
    cmp -s -n "$(stat -c %s "$s/$f")" "$s/$f" "$r/$f" ||
      bad "$s: $f is not the start of the uninterrupted run's"
  done
  if [ -f "$s/$name.pvd" ]; then
    /usr/bin/python3 "$(dirname "${BASH_SOURCE[0]}")/check_vtk.py" --series "$s" "$name" >/dev/null ||
      bad "$s: the series does not read cleanly"
  fi
  echo "  kept: $(wc -l <"$s/energy.csv") energy.csv lines, $(ls "$s" | grep -c '\.vtp$') .vtp," \
    "$(ls "$s/frames" 2>/dev/null | grep -c '\.png$') frames"
}

# same_run REFERENCE RESUMED NAME: every file of the uninterrupted run
# (frames, .vtp, .pvd, CSV tables) identical in the resumed one, no
# other frame, and summary.json's numbers (not wall times) the same, call
# counts included.
same_run() {
  local a=$1 b=$2 name=$3 n=0 f
  for f in "$a"/*.vtp "$a"/frames/*.png; do
    [ -e "$f" ] || continue
    n=$((n + 1))
    cmp -s "$f" "$b/${f#"$a"/}" || bad "${f#"$a"/} differs after resume"
  done
  [ "$(find "$b" -name '*.vtp' -o -name '*.png' | wc -l)" -eq "$n" ] ||
    bad "the resumed run wrote a different number of frames"
  for f in energy.csv probes.csv "$name.pvd"; do
    [ -f "$a/$f" ] || continue
    cmp -s "$a/$f" "$b/$f" || bad "$f differs after resume"
  done
  local keys=(steps dt_min dt_max energy J linear_momentum_drift angular_momentum_drift
    fracture zigzag_max stable error completed calls)
  for key in "${keys[@]}"; do
    [ "$(grep "\"$key\"" "$a/summary.json")" = "$(grep "\"$key\"" "$b/summary.json")" ] ||
      bad "summary.json $key differs after resume"
  done
  echo "  compared $n frames"
}
