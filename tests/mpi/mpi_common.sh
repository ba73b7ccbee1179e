# The frame of the MPI test scripts (sourced after `set -u`, with $sph set):
# a scratch folder removed on exit, check NAME COMMAND... counting checks and
# failures (summary prints them and fails on any), compare (below), the
# mpirun command line
# (one thread a rank, oversubscribed; as root allowed), same_bytes A B (two
# runs' files equal but for the timings) and refused SPH_ARGS... (exit 2 on
# every rank of ${np:-2}, no folder made, the message $expect); fail MESSAGE
# counts a failure found without check; resumed_like and kill_rank_when for
# the checkpoint tests.
# the output fields check_mpi.py compares (particle_id matches the particles)
fields='output.fields=[pressure,velocity,displacement,von_mises,J,stress,body_id,particle_id]'
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
total=0
check() { # name, command...
  local name=$1
  shift
  total=$((total + 1))
  if "$@" >"$work/out.txt" 2>&1; then
    echo "ok   $name"
  else
    echo "FAIL $name"
    tail -20 "$work/out.txt"
    fails=$((fails + 1))
  fi
}
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
mpi=(mpirun --oversubscribe --bind-to none -x OMP_NUM_THREADS=1)
[ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
same_bytes() { # run folder, run folder
  for f in "$1"/* "$1"/frames/*; do
    [ -f "$f" ] || continue # frames/* of a run without frames
    b=${f#"$1/"}
    case $b in summary.json | scene_used.yaml | frames) continue ;; esac
    cmp -s "$f" "$2/$b" || { echo "$b differs"; return 1; }
  done
}
refused() { # sph args...
  local out=$work/refused
  rm -rf "$out"
  "${mpi[@]}" -np "${np:-2}" "$sph" "$@" --out "$out" >"$work/ref.txt" 2>&1
  local rc=$?
  if [ $rc -ne 2 ] || [ -e "$out" ] || ! grep -q "$expect" "$work/ref.txt"; then
    echo "rc $rc, wanted 2; folder made: $([ -e "$out" ] && echo yes || echo no)"
    cat "$work/ref.txt"
    return 1
  fi
}
# resumed_like LABEL WHOLE RESUMED: every file the uninterrupted run wrote
# in WHOLE has the same bytes in RESUMED (but the timings in summary.json,
# the command line in scene_used.yaml and the checkpoints), no .part file
# is left and the resumed run completed
resumed_like() {
  local n=0 f b
  for f in "$2"/*; do
    b=${f#"$2/"}
    case $b in summary.json | scene_used.yaml | checkpoint_*) continue ;; esac
    cmp -s "$f" "$3/$b" || fail "$1: $b differs from the uninterrupted run's"
    n=$((n + 1))
  done
  ls "$3" | grep -q '\.part$' && fail "$1: temporary files left: $(ls "$3" | grep part)"
  grep -q '"completed": true' "$3/summary.json" || fail "$1: not completed"
  echo "$1: $n files compared"
}
rank_of() { pgrep -P "$1" | tail -1; } # a rank mpirun (pid $1) started
# kill_rank_when FILE PID: once FILE is there, kill -9 of a rank of the
# mpirun PID; prints the rank's pid (nothing when the run ended first)
kill_rank_when() {
  while [ ! -f "$1" ] && kill -0 "$2" 2>/dev/null; do
    sleep 0.02
  done
  local victim
  victim=$(rank_of "$2")
  [ -n "$victim" ] && kill -9 "$victim"
  echo "$victim"
}
frames_alike() { # serial dir, MPI dir
  for f in "$1"/frames/*.png; do
    "$sph" imgdiff "$f" "$2/frames/${f##*/}" || return 1
  done
}

# compare NAME SCENE BOUND RANKS... -- SPH_ARGS...: the serial run (one
# thread), then on each rank count the run and check_mpi.py against it
# (BOUND: its REL_TOL and options), the frames alike by sph imgdiff
compare() {
  local name=$1 scene=$2 bound=$3
  shift 3
  local ranks=()
  while [ "$1" != -- ]; do ranks+=("$1"); shift; done
  shift
  OMP_NUM_THREADS=1 "$sph" "$@" --out "$work/$name.serial" >/dev/null ||
    { echo "FAIL $name serial run"; fails=$((fails + 1)); return; }
  for n in "${ranks[@]}"; do
    check "$name np $n runs" "${mpi[@]}" -np "$n" "$sph" "$@" \
      --out "$work/$name.np$n"
    check "$name np $n equals serial" /usr/bin/python3 \
      "$src/tests/mpi/check_mpi.py" "$work/$name.serial" "$work/$name.np$n" \
      "$scene" "$n" $bound
    cat "$work/out.txt"
    if [ -d "$work/$name.serial/frames" ]; then
      check "$name np $n frames alike" frames_alike "$work/$name.serial" \
        "$work/$name.np$n"
    fi
  done
}
summary() {
  echo "$((total - fails)) passed, $fails failed"
  [ $fails -eq 0 ]
}
