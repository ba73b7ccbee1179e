#!/bin/bash
# Every GPU check of sph (docs/gpu.md) in one run: builds nothing, prints
# figures and PASS/FAIL per check, exit 0 when all passed. About 2-4 minutes
# on an H100/H200 (the 1M-particle set-up on the CPU is most of it).
#
#   tests/gpu/run_gpu_checks.sh [BUILD_DIR]        (default: build)
#   tests/gpu/run_gpu_checks.sh --kit              on a lent device machine
#
# --kit runs the programs of a device kit (../shared/tools/device_kit.sh)
# through its loader. Made on this machine from a CUDA build, in the
# checkout the session started in (only that one travels to the device):
#   ../shared/tools/device_kit.sh build/sph build/tests/test_gpu_step \
#       tests/gpu/run_gpu_checks.sh scenes
#   echo /.device/ >> .git/info/exclude
# and run there with carry [".device"]:
#   source .device/kit.sh && bash $K/bin/run_gpu_checks.sh --kit
# The kit's loader takes its own library path, so the driver's libcuda.so.1
# is looked up here and added to it.
set -u
KIT=0
B=build
if [ "${1:-}" = --kit ]; then KIT=1; else B=${1:-build}; fi
fails=0
pass() { echo "PASS $*"; }
fail() { echo "FAIL $*"; fails=$((fails + 1)); }

if [ $KIT = 1 ]; then
  K=$(cd "$(dirname "$0")/.." && pwd) # the kit's root: bin/ holds this script
  # as kit.sh sets it: sph restarts itself through /proc/self/exe (the
  # carried loader) unless the OpenMP wait policy is chosen
  export GOMP_SPINCOUNT=${GOMP_SPINCOUNT:-1000}
  cudadir=
  for d in $(ldconfig -p 2>/dev/null | awk '/libcuda\.so\.1 /{print $NF}' | xargs -r dirname) \
           /usr/local/nvidia/lib64 /usr/lib/x86_64-linux-gnu /usr/lib64 ${LD_LIBRARY_PATH:+${LD_LIBRARY_PATH//:/ }}; do
    [ -e "$d/libcuda.so.1" ] && { cudadir=$d; break; }
  done
  echo "libcuda.so.1: ${cudadir:-not found}"
  run() { local p=$1; shift; "$K/lib/ld-linux-x86-64.so.2" --library-path "$K/lib${cudadir:+:$cudadir}" "$K/bin/$p" "$@"; }
  SCENES=$K/scenes
else
  run() { local p=$1; shift
    case $p in sph) "$B/sph" "$@" ;; *) "$B/tests/$p" "$@" ;; esac; }
  SCENES=$(cd "$(dirname "$0")/../.." && pwd)/scenes
fi
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader

echo "== 1. the device step against the CPU (tl-jst pF, clamped base; plain, JST,"
echo "      the shipped column's JST + projections), the shipped column's energy"
run test_gpu_step --scenes "$SCENES"
rc=$?
[ $rc = 0 ] && pass "device step = CPU (one step 1e-12, 200 steps 1e-9, energy 1e-6, repeatable)" ||
  { [ $rc = 77 ] && fail "no device (SKIP above)" || fail "device step against the CPU (rc $rc)"; }

echo "== 2. throughput: ~1M particles (55 x 330 x 55 column), the shipped column's method"
t0=$(date +%s)
run test_gpu_step --bench 55 && pass "bench 1M ($(( $(date +%s) - t0 )) s)" || fail "bench 1M"

echo "== 3. sph run --device cuda: refused, exit 2, nothing written, until the"
echo "      run loop drives the device step (docs/gpu.md 'Not yet')"
out=$(mktemp -d)/o
msg=$(run sph run "$SCENES/twisting_column.yaml" --device cuda --out "$out" --quiet 2>&1)
rc=$?
echo "$msg"
if [ $rc = 2 ] && [ ! -e "$out" ] && echo "$msg" | grep -q "no GPU path"; then
  pass "--device cuda refused with the reason, exit 2, nothing written"
else
  fail "--device cuda: rc $rc, folder $( [ -e "$out" ] && echo written || echo absent)"
fi
msg=$(run sph check "$SCENES/twisting_column.yaml" --device cuda 2>&1 | tail -6)
echo "$msg"
echo "$msg" | grep -q "method tl-jst" && pass "sph check --device cuda lists where each part runs" ||
  fail "sph check --device cuda"

echo "== $([ $fails = 0 ] && echo "ALL PASS" || echo "$fails FAILED")"
[ $fails = 0 ]
