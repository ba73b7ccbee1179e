#!/bin/bash
# Every GPU check of sph (docs/gpu.md) in one run: builds nothing, prints
# figures and PASS/FAIL per check, exit 0 when all passed. Meant to finish
# in about 3-5 minutes on an H100/H200 (the CPU's set-up of the 1M- and
# 384k-particle columns and the CPU's own twisting column run are most of it).
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

# kinetic, strain and total energy (columns 2-4) of two energy.csv files:
# each column's largest difference relative to its largest |value| within
# tol; prints the worst
energy_close() {
  awk -F, -v tol="$3" '
    NR == FNR { if (FNR > 1) for (c = 2; c <= 4; ++c) v[FNR, c] = $c; next }
    FNR > 1 { rows++
      for (c = 2; c <= 4; ++c) { d = v[FNR, c] - $c; m = $c
        if (d < 0) d = -d; if (m < 0) m = -m
        if (d > dif[c]) dif[c] = d; if (m > big[c]) big[c] = m } }
    END { r = 0; for (c = 2; c <= 4; ++c) { q = big[c] > 0 ? dif[c] / big[c] : dif[c]; if (q > r) r = q }
      printf "%d rows, energies differ by %.3g relative\n", rows, r
      exit !(rows > 1 && r <= tol) }' "$1" "$2"
}
verdict() { grep -h "verdict" "$1" | tail -1; }

echo "== 3. sph run --device cuda: the shipped twisting column to its end (0.3 s)"
echo "      against the CPU's run: verdict and energy.csv within 1e-6 relative"
o=$(mktemp -d)
run sph run "$SCENES/twisting_column.yaml" --set output.png=false --out "$o/cpu" >"$o/cpu.log" 2>&1
run sph run "$SCENES/twisting_column.yaml" --set output.png=false --device cuda --out "$o/gpu" >"$o/gpu.log" 2>&1
rc=$?
echo "CPU: $(verdict "$o/cpu.log")"
echo "GPU: $(verdict "$o/gpu.log")"
[ $rc = 0 ] && [ "$(verdict "$o/cpu.log" | cut -d'(' -f1)" = "$(verdict "$o/gpu.log" | cut -d'(' -f1)" ] &&
  energy_close "$o/cpu/energy.csv" "$o/gpu/energy.csv" 1e-6 &&
  pass "twisting column on the GPU: the CPU's verdict and energies" ||
  { tail -3 "$o/gpu.log"; fail "twisting column on the GPU (rc $rc)"; }

echo "== 3b. the other shipped scenes the device step covers, 200 steps each:"
echo "      energy.csv within 1e-6 relative of the CPU's"
for sc in bending_column column_energy spinning_cube tensile_cube twisting_column_extreme; do
  f=$SCENES/$sc.yaml
  plan=$(run sph check "$f")
  dt=$(echo "$plan" | sed -n 's/.*first dt \([0-9.e+-]*\) s.*/\1/p' | head -1)
  tend=$(echo "$plan" | sed -n 's/.*time *end \([0-9.e+-]*\) s.*/\1/p' | head -1)
  end=$(awk -v d="$dt" -v t="$tend" 'BEGIN { e = 200 * d; if (t < e) e = t; printf "%.6g", e }')
  every=$(awk -v e="$end" 'BEGIN { printf "%.6g", e / 4 }')
  sets=(--set output.png=false --set time.end=$end --set output.every=$every)
  run sph run "$f" "${sets[@]}" --out "$o/c_$sc" >"$o/c_$sc.log" 2>&1
  run sph run "$f" "${sets[@]}" --device cuda --out "$o/g_$sc" >"$o/g_$sc.log" 2>&1
  rc=$?
  echo "$sc: CPU $(verdict "$o/c_$sc.log"); GPU $(verdict "$o/g_$sc.log")"
  [ $rc = 0 ] && energy_close "$o/c_$sc/energy.csv" "$o/g_$sc/energy.csv" 1e-6 &&
    pass "$sc on the GPU" || { tail -2 "$o/g_$sc.log"; fail "$sc on the GPU (rc $rc)"; }
done

echo "== 4. sph run --device cuda at 384,000 particles (40 x 240 x 40), 0.002 s"
run sph run "$SCENES/twisting_column.yaml" --set output.png=false --device cuda \
  --set 'bodies.0.particles.count=[40,240,40]' --set time.end=0.002 --set output.every=0.001 \
  --out "$o/big" >"$o/big.log" 2>&1 && pass "384k on the GPU: $(verdict "$o/big.log")" ||
  { tail -3 "$o/big.log"; fail "384k on the GPU"; }

echo "== 5. refusals: a method without a GPU path, exit 2, nothing written"
msg=$(run sph run "$SCENES/colliding_rings.yaml" --device cuda --out "$o/rings" 2>&1)
rc=$?
echo "$msg"
[ $rc = 2 ] && [ ! -e "$o/rings" ] && echo "$msg" | grep -q "no GPU path" &&
  pass "ul-sph --device cuda refused" || fail "ul-sph --device cuda: rc $rc"
run sph check "$SCENES/twisting_column.yaml" --device cuda | tail -5
rm -rf "$o"

echo "== $([ $fails = 0 ] && echo "ALL PASS" || echo "$fails FAILED")"
[ $fails = 0 ]
