# The frame of the MPI test scripts (sourced after `set -u`): a scratch
# folder removed on exit, check NAME COMMAND... counting failures, the
# mpirun command line (one thread a rank, oversubscribed; as root allowed)
# and same_bytes A B (two runs' files equal but for the timings).
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
check() { # name, command...
  local name=$1
  shift
  if "$@" >"$work/out.txt" 2>&1; then
    echo "ok   $name"
  else
    echo "FAIL $name"
    tail -20 "$work/out.txt"
    fails=$((fails + 1))
  fi
}
mpi=(mpirun --oversubscribe --bind-to none -x OMP_NUM_THREADS=1)
[ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
same_bytes() { # run folder, run folder
  for f in "$1"/* "$1"/frames/*; do
    b=${f#"$1/"}
    case $b in summary.json | scene_used.yaml | frames) continue ;; esac
    cmp -s "$f" "$2/$b" || { echo "$b differs"; return 1; }
  done
}
