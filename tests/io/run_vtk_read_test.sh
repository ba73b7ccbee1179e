#!/usr/bin/env bash
# `sph render` reads back the VTK files (issue 36 item 2): a malformed .pvd
# (a DataSet tag left open, which crashed the old reader with exit 139) or
# a damaged piece is refused with exit 2 naming the file and line, and no
# output folder is left behind; a FIFO given as a .vtp is refused, not
# waited on; and the .pvtp of a run over MPI ranks (pieces in rank order,
# without particle_id) is drawn again into the run's own frames, byte for
# byte (skipped without mpirun or an MPI build).
# Usage: SPH SRC [MPI] (MPI: 1 in a build with MPI, from CMake)
set -u
sph=$1
src=$2
with_mpi=${3:-0}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
scene=$src/scenes/colliding_balls_3d.yaml
args=(--threads 1 --quiet --set time.end=0.002 --set 'output.png={width: 96, height: 64}'
  --set bodies.0.particles.spacing=0.004 --set bodies.1.particles.spacing=0.004
  --set 'output.fields=[pressure, velocity, J]')

# refused RUN WHAT PATTERN: exit 2, the message matches, no RUN/render
refused() {
  local run=$1 what=$2 pattern=$3
  timeout 60 "$sph" render "$run" >"$work/log" 2>&1
  local rc=$?
  [ $rc -eq 2 ] || fail "$what: exit $rc, expected 2: $(tail -2 "$work/log")"
  grep -q -- "$pattern" "$work/log" || fail "$what: message $(tail -2 "$work/log")"
  [ ! -e "$run/render" ] || fail "$what: left $run/render behind"
}

"$sph" run "$scene" --out "$work/serial" "${args[@]}" >/dev/null 2>&1 || fail "the serial run"
cp -a "$work/serial" "$work/open_tag"
# the first DataSet's '/>' lost: its tag runs into the next one
/usr/bin/python3 - "$work/open_tag/colliding_balls_3d.pvd" <<'PY'
import sys
p = sys.argv[1]
s = open(p).read()
i = s.index('.vtp"/>') + len('.vtp"/')
open(p, "w").write(s[:i] + s[i + 1:])
PY
refused "$work/open_tag" "a DataSet tag left open" "colliding_balls_3d.pvd:4:"
cp -a "$work/serial" "$work/fifo"
rm "$work/fifo/colliding_balls_3d_0002.vtp"
mkfifo "$work/fifo/colliding_balls_3d_0002.vtp"
refused "$work/fifo" "a FIFO as a .vtp" "not a regular file"

mpirun=$(command -v mpirun || true)
if [ -n "$mpirun" ] && [ "$with_mpi" = 1 ]; then
  mpi=(mpirun --oversubscribe --bind-to none -x OMP_NUM_THREADS=1 -np 2)
  [ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
  if "${mpi[@]}" "$sph" run "$scene" --out "$work/ranks" "${args[@]}" >"$work/log" 2>&1; then
    "$sph" render "$work/ranks" --out "$work/redrawn" >"$work/log" 2>&1 ||
      fail "render of a run over 2 ranks: $(tail -2 "$work/log")"
    n=0
    for f in "$work"/ranks/frames/*.png; do
      n=$((n + 1))
      cmp -s "$f" "$work/redrawn/frames/$(basename "$f")" || fail "$(basename "$f") drawn again differs"
    done
    [ $n -eq 5 ] || fail "$n frames in the run over 2 ranks, expected 5"
    truncate -s 100 "$work/ranks/colliding_balls_3d_0003_p1.vtp"
    refused "$work/ranks" "a piece cut short" "colliding_balls_3d_0003_p1.vtp:"
  else
    fail "the run over 2 ranks: $(tail -3 "$work/log")"
  fi
else
  echo "skipped: the .pvtp of a run over MPI ranks (no mpirun or no MPI build)"
fi

[ $fails -eq 0 ] && echo "vtk reading: checked"
[ $fails -eq 0 ]
