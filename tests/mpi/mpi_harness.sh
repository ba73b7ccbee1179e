# Shared by the MPI test scripts (sourced, after sph=$1): a temporary
# folder $work removed on exit, the failure counter with fail MESSAGE, and
# the launcher mpi=(mpirun ...) oversubscribing the machine's cores, one
# thread a rank (--allow-run-as-root as root).
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
mpi=(mpirun --oversubscribe --bind-to none -x OMP_NUM_THREADS=1)
[ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
