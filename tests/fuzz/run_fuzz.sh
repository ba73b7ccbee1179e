#!/usr/bin/env bash
# Fuzzes the scene loader (tests/fuzz/fuzz_scene.c), the VTK reader
# (fuzz_vtk.c: .pvd, .vtp, .pvtp), the checkpoint reader
# (fuzz_checkpoint.c) and the mesh reader with the inside test
# (fuzz_mesh.c) for SECONDS in all (default 60: half to the scene loader,
# the rest shared equally by the others) under AddressSanitizer and UBSan:
# builds them with clang into build-fuzz (SPH_FUZZ_BUILD overrides; nothing
# is installed: clang and libFuzzer come from ./bootstrap.sh --with-fuzz),
# replays each one's regression inputs (tests/fuzz/regressions/,
# regressions_vtk/, regressions_checkpoint/, regressions_mesh/), then fuzzes each from its seed
# corpus (the scene loader: every shipped scene, the bad scenes of
# tests/cli/bad and its regressions; the readers: their regressions and, for
# the checkpoint, a valid checkpoint the target writes) and the corpus kept
# in build-fuzz/fuzz/corpus[_vtk|_checkpoint] from earlier runs, one process
# each. Prints the executions per second; exit 0 when nothing was found, 1
# with the input that crashed (build-fuzz/fuzz/artifacts/), 2 when it cannot
# build. SPH_FUZZ_TARGETS="vtk checkpoint" fuzzes only those (the time is
# shared among them).
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
targets=(${SPH_FUZZ_TARGETS:-scene vtk checkpoint mesh})
cmake --build "$build" -j2 --target "${targets[@]/#/fuzz_}" >"$out/build.log" 2>&1 ||
  { tail -40 "$out/build.log" >&2; exit 2; }
symbolizer=$(command -v llvm-symbolizer || command -v llvm-symbolizer-14 || true)
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
[ -n "$symbolizer" ] && export ASAN_SYMBOLIZER_PATH=$symbolizer
export GOMP_SPINCOUNT=1000 OMP_NUM_THREADS=1

# the time budget shared out: the scene loader half (all of it alone), the
# readers the rest in equal parts; at least 1 s each
share() { # target
  local n=${#targets[@]} scene=0 t
  for t in "${targets[@]}"; do [ "$t" = scene ] && scene=1; done
  if [ "$n" -eq 1 ]; then
    echo "$secs"
  elif [ "$scene" -eq 1 ] && [ "$1" = scene ]; then
    echo $((secs / 2 > 0 ? secs / 2 : 1))
  elif [ "$scene" -eq 1 ]; then
    echo $(((secs - secs / 2) / (n - 1) > 0 ? (secs - secs / 2) / (n - 1) : 1))
  else
    echo $((secs / n > 0 ? secs / n : 1))
  fi
}

# fuzz TARGET: replays its regressions, then fuzzes it for its share
fuzz_one() {
  local t=$1 fuzz=$build/tests/fuzz/fuzz_$1 sfx=_$1 regdir=regressions_$1
  local -a args extra regressions
  [ "$t" = scene ] && sfx= && regdir=regressions
  local seeds=$out/seeds$sfx corpus=$out/corpus$sfx log=$out/fuzz$sfx.log
  rm -rf "$seeds"
  mkdir -p "$seeds" "$corpus" "$out/artifacts"
  regressions=("$src/tests/fuzz/$regdir"/*)
  cp "${regressions[@]}" "$seeds/"
  case $t in
  scene)
    cp "$src"/scenes/*.yaml "$src"/tests/cli/bad/* "$seeds/"
    # -timeout: one input may take 30 s (the sanitizers slow the particle
    # generation 20-fold; the shipped rings' relaxation takes 6 s); -max_len:
    # scenes are a few kB
    extra=(-timeout=30 -max_len=16384 -dict="$src/tests/fuzz/scene.dict") ;;
  vtk) extra=(-timeout=10 -max_len=65536) ;;
  mesh) extra=(-timeout=10 -max_len=65536) ;;
  checkpoint)
    export SPH_FUZZ_SEED_DIR=$seeds
    extra=(-timeout=10 -max_len=16384) ;;
  esac
  # the inputs that once crashed must not crash again
  "$fuzz" -timeout=30 "${regressions[@]}" >"$out/regressions$sfx.log" 2>&1 ||
    { tail -60 "$out/regressions$sfx.log" >&2; echo "run_fuzz.sh: a regression input of fuzz_$t crashes again" >&2; return 1; }
  echo "fuzz_$t: ${#regressions[@]} regression inputs replayed"
  local s
  s=$(share "$t")
  args=(-max_total_time="$s" -rss_limit_mb=2048 "${extra[@]}"
    -artifact_prefix="$out/artifacts/" -print_final_stats=1)
  [ "$jobs" -gt 1 ] && args+=(-jobs="$jobs" -workers="$jobs")
  set +e
  rm -f "$out"/fuzz-*.log
  # with -jobs each worker logs to fuzz-N.log in the working folder
  (cd "$out" && "$fuzz" "${args[@]}" "$corpus" "$seeds") >"$log" 2>&1
  local rc=$?
  set -e
  unset SPH_FUZZ_SEED_DIR
  for f in "$out"/fuzz-*.log; do
    [ -f "$f" ] && cat "$f" >>"$log"
  done
  local execs rate found
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | awk '{s += $1} END {print s}')
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | awk '{s += $1} END {print s}')
  echo "fuzz_$t: ${execs:-?} inputs in $s s (${rate:-?} exec/s), corpus $(ls "$corpus" | wc -l) files; log $log"
  found=$(sed -n "s/.*Test unit written to //p" "$log" | tail -1)
  if [ $rc -ne 0 ] || [ -n "$found" ]; then
    grep -E "^(==[0-9]+==ERROR|SUMMARY|.*runtime error|fuzz_$t:)" "$log" | head -10 >&2 || true
    echo "run_fuzz.sh: fuzz_$t found ${found:-a failure (exit $rc)}; replay it with $fuzz FILE," >&2
    echo "  fix it and add it to tests/fuzz/$regdir/ (ctest -R fuzz_regressions replays them)" >&2
    return 1
  fi
}

status=0
for t in "${targets[@]}"; do
  fuzz_one "$t" || status=1
done
exit $status
