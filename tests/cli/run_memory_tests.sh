#!/usr/bin/env bash
# The memory estimate (issue 36 item 3): the limits it compares with (a
# memory cgroup, v2 and v1, from a fake tree under SPH_CGROUP_ROOT; ulimit
# -v), the png frame buffers in it, sph render's use of it, and out of
# memory while loading a scene (exit 3, naming what could not be allocated).
set -u
sph=$1
src=$2
here=$(cd "$(dirname "$0")" && pwd)
. "$(dirname "$0")/harness.sh"
col="$src/scenes/twisting_column.yaml"
big='bodies.0.particles.count=[40,200,40]' # 320,000 particles, about 0.9 GB

# (a) a memory cgroup's limit: v2 memory.max less memory.current
mkdir -p "$work/cg2" "$work/cg1/memory"
echo 400000000 >"$work/cg2/memory.max"
echo 0 >"$work/cg2/memory.current"
SPH_CGROUP_ROOT="$work/cg2" "$sph" check "$col" --set "$big" >/dev/null 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "the memory cgroup's limit of 400 MB" "$work/stderr" && ok ||
  bad "cgroup v2: $(cat "$work/stderr")"
# v1 memory.limit_in_bytes less memory.usage_in_bytes
echo 300000000 >"$work/cg1/memory/memory.limit_in_bytes"
echo 100000000 >"$work/cg1/memory/memory.usage_in_bytes"
SPH_CGROUP_ROOT="$work/cg1" "$sph" run "$col" --set "$big" --out "$work/o1" >/dev/null 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "the memory cgroup's limit of 300 MB leaves 200 MB" "$work/stderr" &&
  [ ! -e "$work/o1" ] && ok || bad "cgroup v1: $(cat "$work/stderr")"
# "max" is no limit
echo max >"$work/cg2/memory.max"
SPH_CGROUP_ROOT="$work/cg2" "$sph" check "$col" >/dev/null 2>"$work/stderr" && ok ||
  bad "cgroup v2 max: $(cat "$work/stderr")"
# RLIMIT_AS (ulimit -v 1 GB)
(ulimit -v 1000000 && exec "$sph" check "$col" --set "$big") >/dev/null 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "the address-space limit (ulimit -v) of 1.02 GB" "$work/stderr" && ok ||
  bad "ulimit -v: $(cat "$work/stderr")"

# (c) the frame buffers: 16384 x 16384 needs 4.3 GB
"$sph" check "$col" --set output.png.width=16384 --set output.png.height=16384 \
  --max-memory 1G >/dev/null 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "the 16384 x 16384 frames need about 4.29 GB" "$work/stderr" && ok ||
  bad "16384^2 frames: $(cat "$work/stderr")"

# (d) sph render applies the estimate to scene_used.yaml's particles
"$sph" run punch --set time.end=0.00002 --set output.every=0.00001 --out "$work/r" --quiet >/dev/null 2>&1
echo 1000000 >"$work/cg2/memory.max"
SPH_CGROUP_ROOT="$work/cg2" "$sph" render "$work/r" --out "$work/r/again" >/dev/null 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "the memory cgroup's limit of 1 MB" "$work/stderr" && [ ! -e "$work/r/again" ] && ok ||
  bad "render under a 1 MB cgroup: $(cat "$work/stderr")"

# (f) out of memory while loading: exit 3 naming what, never 2 "scene tree";
# a scene copied through aliases, under a small ulimit -v
head -22 "$src/tests/cli/bad/alias_bomb.yaml" | tail -n +2 >"$work/laughs.yaml"
seen=0
for v in 200000 210000 220000 230000 240000 260000 280000 300000; do
  (ulimit -v $v && exec "$sph" check "$work/laughs.yaml") >/dev/null 2>"$work/stderr"
  rc=$?
  if grep -q "scene tree\|YAML parser" "$work/stderr" && [ $rc -ne 3 ]; then
    bad "ulimit -v $v: exit $rc: $(cat "$work/stderr")"
  elif [ $rc -eq 3 ] && grep -q "no memory for the" "$work/stderr"; then
    seen=1
  fi
done
[ $seen -eq 1 ] && ok || bad "no out-of-memory exit 3 seen while loading"

# (b) the estimate bounds the peak resident set's growth with the particles
peak() { # peak RSS in kB of a two-frame run of scene $1 with --set $2 $3
  rm -rf "$work/p"
  /usr/bin/time -f %M -o "$work/rss" "$sph" run "$1" --set "$2" --set "$3" \
    --set output.every=0.000001 --set time.end=0.000002 --threads 1 --quiet --out "$work/p" >/dev/null 2>&1
  tail -1 "$work/rss"
}
grows() { # name scene small large (--set assignments of the particles)
  local a b g
  a=$(peak "$2" "$3" "$4")
  b=$(peak "$2" "$5" "$6")
  g=$((b - a))
  # the larger scene's estimate is above the growth: --max-memory refuses it
  "$sph" check "$2" --set "$5" --set "$6" --set output.every=0.000001 --set time.end=0.000002 --max-memory $((g > 1024 ? g : 1024))k >/dev/null 2>"$work/stderr"
  [ $? -eq 2 ] && grep -qF "the limit (--max-memory)" "$work/stderr" && ok ||
    bad "$1: peak grew ${g} kB, more than the estimate: $(cat "$work/stderr")"
}
if [ -x /usr/bin/time ]; then
  grows twisting_column "$col" 'bodies.0.particles.count=[7,37,7]' 'time.end=0.000002' \
    'bodies.0.particles.count=[13,67,13]' 'time.end=0.000002'
  grows colliding_rings colliding_rings 'bodies.0.particles.spacing=0.001' 'bodies.1.particles.spacing=0.001' \
    'bodies.0.particles.spacing=0.0006' 'bodies.1.particles.spacing=0.0006'
fi

echo "memory: $pass passed, $fail failed"
[ $fail -eq 0 ]
