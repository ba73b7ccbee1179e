#!/usr/bin/env bash
# Fuzzes the scene loader (tests/fuzz/fuzz_scene.c) for SECONDS (default
# 60) under AddressSanitizer and UBSan: builds it with clang into
# build-fuzz (SPH_FUZZ_BUILD overrides; nothing is installed: clang and
# libFuzzer come from ./bootstrap.sh --with-fuzz), replays
# tests/fuzz/regressions/, then fuzzes from the seed corpus (every shipped
# scene, the bad scenes of tests/cli/bad, the regressions) and the corpus
# kept in build-fuzz/fuzz/corpus from earlier runs, one process. Prints the
# executions per second; exit 0 when nothing was found, 1 with the input
# that crashed (build-fuzz/fuzz/artifacts/), 2 when it cannot build.
#   tests/fuzz/run_fuzz.sh 3600          # an hour
#   SPH_FUZZ_JOBS=2 tests/fuzz/run_fuzz.sh 600   # two workers
set -euo pipefail
secs=${1:-60}
case "$secs" in
'' | *[!0-9]*) echo "usage: tests/fuzz/run_fuzz.sh [SECONDS]" >&2; exit 2 ;;
esac
src=$(cd "$(dirname "$0")/../.." && pwd)
build=${SPH_FUZZ_BUILD:-$src/build-fuzz}
jobs=${SPH_FUZZ_JOBS:-1}
cc=$(command -v clang || command -v clang-14 || true)
if [ -z "$cc" ]; then
  echo "run_fuzz.sh: clang not found (./bootstrap.sh --with-fuzz installs it)" >&2
  exit 2
fi
out=$build/fuzz
mkdir -p "$out"
cmake -S "$src" -B "$build" -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSPH_FUZZ=ON -DSPH_BUILD_TESTS=OFF >"$out/configure.log" 2>&1 ||
  { cat "$out/configure.log" >&2; exit 2; }
cmake --build "$build" -j2 --target fuzz_scene >"$out/build.log" 2>&1 ||
  { tail -40 "$out/build.log" >&2; exit 2; }
fuzz=$build/tests/fuzz/fuzz_scene
rm -rf "$out/seeds"
mkdir -p "$out/seeds" "$out/corpus" "$out/artifacts"
cp "$src"/scenes/*.yaml "$src"/tests/cli/bad/* "$out/seeds/"
regressions=("$src"/tests/fuzz/regressions/*)
cp "${regressions[@]}" "$out/seeds/"
symbolizer=$(command -v llvm-symbolizer || command -v llvm-symbolizer-14 || true)
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
[ -n "$symbolizer" ] && export ASAN_SYMBOLIZER_PATH=$symbolizer
export GOMP_SPINCOUNT=1000 OMP_NUM_THREADS=1

# the inputs that once crashed must not crash again
"$fuzz" -timeout=30 "${regressions[@]}" >"$out/regressions.log" 2>&1 ||
  { tail -60 "$out/regressions.log" >&2; echo "run_fuzz.sh: a regression input crashes again" >&2; exit 1; }
echo "fuzz: ${#regressions[@]} regression inputs replayed"

# -timeout: one input may take 30 s (the sanitizers slow the particle
# generation 20-fold; the shipped rings' relaxation takes 6 s); -max_len:
# scenes are a few kB
args=(-max_total_time="$secs" -timeout=30 -rss_limit_mb=2048 -max_len=16384
  -dict="$src/tests/fuzz/scene.dict" -artifact_prefix="$out/artifacts/"
  -print_final_stats=1)
[ "$jobs" -gt 1 ] && args+=(-jobs="$jobs" -workers="$jobs")
set +e
rm -f "$out"/fuzz-*.log
# with -jobs each worker logs to fuzz-N.log in the working folder
(cd "$out" && "$fuzz" "${args[@]}" "$out/corpus" "$out/seeds") >"$out/fuzz.log" 2>&1
rc=$?
set -e
for f in "$out"/fuzz-*.log; do
  [ -f "$f" ] && cat "$f" >>"$out/fuzz.log"
done
execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/fuzz.log" | awk '{s += $1} END {print s}')
rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$out/fuzz.log" | awk '{s += $1} END {print s}')
echo "fuzz: ${execs:-?} inputs in ${secs} s (${rate:-?} exec/s), corpus $(ls "$out/corpus" | wc -l) files; log $out/fuzz.log"
found=$(sed -n "s/.*Test unit written to //p" "$out/fuzz.log" | tail -1)
if [ $rc -ne 0 ] || [ -n "$found" ]; then
  grep -E "^(==[0-9]+==ERROR|SUMMARY|.*runtime error|fuzz_scene:)" "$out/fuzz.log" | head -10 >&2 || true
  echo "run_fuzz.sh: found ${found:-a failure (exit $rc)}; replay it with $fuzz FILE," >&2
  echo "  fix it and add it to tests/fuzz/regressions/ (ctest -R fuzz_regressions replays them)" >&2
  exit 1
fi
