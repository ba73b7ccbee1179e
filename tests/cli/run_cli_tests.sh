#!/usr/bin/env bash
# Command-line behaviour: every bad scene in bad/ is refused by `sph check`
# and `sph run` with exit status 2, the message its first line expects
# ("# expect: LINE:COL: key: message") on stderr, and nothing written; plus
# usage errors, a tiny end-to-end run and the --overwrite guard.
set -u
sph=$1
src=$2
here=$(cd "$(dirname "$0")" && pwd)
. "$(dirname "$0")/harness.sh"

for f in "$here"/bad/*.yaml; do
  name=$(basename "$f" .yaml)
  expect=$(head -1 "$f" | sed 's/^# expect: //')
  for cmd in check run; do
    out="$work/out_$name"
    if [ "$cmd" = run ]; then
      "$sph" run "$f" --out "$out" >"$work/stdout" 2>"$work/stderr"
    else
      "$sph" check "$f" >"$work/stdout" 2>"$work/stderr"
    fi
    rc=$?
    if [ $rc -ne 2 ]; then
      bad "$name ($cmd): exit $rc, expected 2: $(cat "$work/stderr")"
    elif ! grep -qF "$f:$expect" "$work/stderr"; then
      bad "$name ($cmd): expected '$f:$expect', got: $(cat "$work/stderr")"
    elif [ -e "$out" ]; then
      bad "$name ($cmd): wrote $out"
    else
      ok
    fi
  done
done

# an analytic initial state the material cannot have: refused at check
for u0 in 1e20 1e308; do
  "$sph" check "$src/scenes/swinging_cube.yaml" --set reference.U0=$u0 2>"$work/stderr" >/dev/null
  [ $? -eq 2 ] && grep -q "<command line>:1:14: reference.U0: the analytic initial state is" "$work/stderr" && ok ||
    bad "reference.U0=$u0: $(cat "$work/stderr")"
done

# a missing file, a bad --set and usage errors
"$sph" check "$work/none.yaml" 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "$work/none.yaml" "$work/stderr" && ok || bad "missing file"
"$sph" check "$src/scenes/twisting_column.yaml" --set materials.rubber.poisson=0.4 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "did you mean 'poisson_ratio'" "$work/stderr" && ok || bad "--set typo: $(cat "$work/stderr")"
"$sph" check "$src/scenes/twisting_column.yaml" --set bodies.3.name=x 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "past the end" "$work/stderr" && ok || bad "--set index: $(cat "$work/stderr")"
# a --set error is the command line's, also where it combines with a scene
# key (issue 36 item 7), and no 300-digit counts (item 8)
"$sph" check "$src/scenes/spinning_cube.yaml" --set time.end=1e300 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "sph: <command line>:1:10: time.end: " "$work/stderr" &&
  ! grep -qE '[0-9]{20}' "$work/stderr" && ok || bad "--set time.end: $(cat "$work/stderr")"
"$sph" check "$src/scenes/spinning_cube.yaml" --set time.end=1e-9 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "sph: <command line>:1:10: time.end: " "$work/stderr" && ok || bad "--set short end: $(cat "$work/stderr")"
"$sph" check "$src/scenes/spinning_cube.yaml" --set output.every=1e-300 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "<command line>:1:14: output.every: 1e+299 output frames" "$work/stderr" && ok || bad "--set every: $(cat "$work/stderr")"
# an error the file's key reports but a --set caused: the note names it
for cmd in check "run --out $work/moved"; do
  "$sph" $cmd "$src/scenes/punch.yaml" --set 'bodies.0.shape.box.min=[0.5,0,0]' 2>"$work/stderr" >/dev/null
  [ $? -eq 2 ] && grep -qF "punch.yaml:22:5: boundaries[1].select: boundary 'left' selects no particle" "$work/stderr" &&
    grep -qF "note: the command line changed this scene (--set bodies.0.shape.box.min); the error may follow from it" "$work/stderr" &&
    [ ! -e "$work/moved" ] && ok || bad "--set moved box ($cmd): $(cat "$work/stderr")"
done
"$sph" check "$src/scenes/punch.yaml" --set 'bodies.0.shape.box.min=[0.5,0,0' 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && ! grep -qF "note:" "$work/stderr" && ok || bad "--set syntax error gets no note: $(cat "$work/stderr")"
"$sph" run "$src/scenes/spinning_cube.yaml" --out "$work/tiny" --set materials.rubber.density=1e-300 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -qF "<command line>:1:26: materials.rubber.density: body cube would need" "$work/stderr" &&
  [ ! -e "$work/tiny" ] && ok || bad "--set density 1e-300: $(cat "$work/stderr")"
# a --set inside a key (a list element, a map's key) or found wrong only
# once the particles exist is the command line's error too (item 7)
"$sph" check "$src/scenes/punch.yaml" --set method.jst.eps2_p=-1 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "sph: <command line>:1:19: method.jst.eps2_p: JST coefficients" "$work/stderr" && ok ||
  bad "--set method.jst.eps2_p: $(cat "$work/stderr")"
"$sph" check "$src/scenes/punch.yaml" --set output.probes.0.at.0=-1 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "sph: <command line>:1:22: output.probes[0].at[0]: probe 'punch_centre'" "$work/stderr" && ok ||
  bad "--set probe outside: $(cat "$work/stderr")"
"$sph" check "$src/scenes/punch.yaml" --set bodies.0.particles.count.1=1 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "sph: <command line>:1:" "$work/stderr" && ok ||
  bad "--set count element: $(cat "$work/stderr")"
"$sph" check "$src/scenes/punch.yaml" --set materials.soft.youngs_modulus=1e300 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "sph: <command line>:1:31: materials.soft.youngs_modulus: body block would need" "$work/stderr" && ok ||
  bad "--set youngs_modulus 1e300: $(cat "$work/stderr")"
# a singular moment matrix names the scene file, the body and the particle's
# position (issue 36 item 7)
"$sph" check "$src/scenes/spinning_cube.yaml" --set kernel.h_over_dp=0.9 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "spinning_cube.yaml:18:5: body cube: singular" "$work/stderr" &&
  grep -qF "at particle 0 (-0.5, -0.5, -0.5)" "$work/stderr" && ok || bad "singular: $(cat "$work/stderr")"
# tl-jst's default CFL follows the integrator (issue 33): SSP-RK3 1.2, 4x
# TVD-RK2's 0.3 on the same state; an explicit cfl wins
dt_of() { "$sph" check "$src/scenes/twisting_column.yaml" --set "method=$1" 2>&1 |
  sed -n 's/.*first dt \([0-9.e+-]*\) s.*/\1/p'; }
d2=$(dt_of "{name: tl-jst}")
d3=$(dt_of "{name: tl-jst, integrator: ssp-rk3}")
d3e=$(dt_of "{name: tl-jst, integrator: ssp-rk3, cfl: 0.3}")
python3 -c "import sys; a,b,c=map(float,sys.argv[1:]); assert abs(b/a-4)<1e-3 and c==a" \
  "$d2" "$d3" "$d3e" 2>/dev/null && ok || bad "tl-jst default cfl: dt $d2 / $d3 / $d3e"
# wave_speed_every holds the current wave speed K steps: the first step is
# the same; 0 is refused naming the key
[ "$(dt_of "{name: tl-jst, wave_speed_every: 10}")" = "$d2" ] && ok || bad "wave_speed_every 10: first dt"
"$sph" check "$src/scenes/twisting_column.yaml" --set method.wave_speed_every=0 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "method.wave_speed_every: wave_speed_every must be in" "$work/stderr" && ok ||
  bad "wave_speed_every 0: $(cat "$work/stderr")"
"$sph" frobnicate 2>/dev/null
[ $? -eq 2 ] && ok || bad "unknown command"
"$sph" run --threads 0 2>/dev/null
[ $? -eq 2 ] && ok || bad "bad --threads"

# an output folder that cannot be created: clear error, nothing written
touch "$work/plainfile"
"$sph" run "$src/scenes/twisting_column.yaml" --out "$work/plainfile/out" --quiet >/dev/null 2>"$work/stderr"
rc=$?
[ $rc -ne 0 ] && grep -qF "$work/plainfile/out" "$work/stderr" && [ ! -e "$work/plainfile/out" ] && ok ||
  bad "unwritable output (exit $rc): $(cat "$work/stderr")"

# a tiny run end to end, then the overwrite guard; 3 x 7 x 3 particles
# (0.5 m across, 1 m along) resolve nothing at the particle scale (the
# zig-zag indicator does not judge so coarse a body)
tiny="$work/tiny.yaml"
sed -e 's/count: \[7, 37, 7\]/count: [3, 7, 3]/' -e 's/end: 0.3/end: 0.02/' \
  -e 's/every: 0.005/every: 0.005/' \
  "$src/scenes/twisting_column.yaml" >"$tiny"
"$sph" run "$tiny" --out "$work/run" --quiet >"$work/stdout" 2>&1
rc=$?
if [ $rc -eq 0 ] && [ -f "$work/run/summary.json" ] && [ -f "$work/run/energy.csv" ] &&
  [ -f "$work/run/probes.csv" ] && [ -f "$work/run/scene_used.yaml" ] &&
  [ -f "$work/run/twisting_column.pvd" ] && [ -f "$work/run/twisting_column_0004.vtp" ] &&
  [ "$(wc -l <"$work/run/energy.csv")" -eq 6 ] && ! ls "$work/run"/*.part >/dev/null 2>&1; then
  ok
else
  bad "tiny run (exit $rc): $(cat "$work/stdout"); $(ls "$work/run" 2>&1)"
fi
"$sph" check "$work/run/scene_used.yaml" >/dev/null 2>&1 && ok || bad "scene_used.yaml does not load back"
"$sph" run "$tiny" --out "$work/run" --quiet >/dev/null 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF -- "--overwrite" "$work/stderr" && ok || bad "second run without --overwrite"
"$sph" run "$tiny" --out "$work/run" --quiet --overwrite >/dev/null 2>&1 && ok || bad "--overwrite"

# an unstable run: exit 1, the verdict line names the first indicator and
# its time, summary.json has it and every indicator's trip time
"$sph" run "$src/scenes/twisting_column.yaml" --out "$work/unstable" --quiet \
  --set method.cfl=1.5 --set time.end=0.1 --set output.every=0.05 \
  --set output.png=off >"$work/stdout" 2>"$work/stderr"
rc=$?
if [ $rc -eq 1 ] &&
  grep -qE '^verdict: UNSTABLE - nan tripped at t = [0-9.e-]+ s: ' "$work/stdout" &&
  python3 - "$work/unstable/summary.json" <<'PY'; then
import json, sys
s = json.load(open(sys.argv[1]))
i = s["indicators"]
assert s["first_indicator"] == "nan" and s["stable"] is False, s
assert i["nan"] == s["tripped_at"] and 0 < i["nan"] < 0.05, i
assert all(i[k] is None for k in i if k != "nan"), i
assert set(i) == {"nan", "jacobian", "energy_growth", "checkerboard",
                  "fracture", "zigzag", "step"}, i
PY
  ok
else
  bad "unstable run (exit $rc): $(cat "$work/stdout" "$work/stderr")"
fi
"$sph" run "$tiny" --out "$work/run" --quiet --overwrite >"$work/stdout" 2>&1
grep -q '"first_indicator": null' "$work/run/summary.json" && ok ||
  bad "stable run: first_indicator not null"

# the OpenMP wait policy: without the user's choice a run spins briefly
# (GOMP_SPINCOUNT=1000) then sleeps; a user's OMP_WAIT_POLICY or
# GOMP_SPINCOUNT is kept as given
spin_of() { # prints the GOMP_SPINCOUNT/OMP_WAIT_POLICY the running sph sees
  env "$@" "$sph" run twisting_column --out "$work/spin" --overwrite --quiet \
    --set time.end=1 --set output.png=false --set output.vtk=false \
    >/dev/null 2>&1 &
  local pid=$! seen=""
  for _ in $(seq 50); do
    sleep 0.1
    seen=$(tr '\0' '\n' <"/proc/$pid/environ" 2>/dev/null |
      grep -E '^(GOMP_SPINCOUNT|OMP_WAIT_POLICY)=' | sort | tr '\n' ' ')
    [ -n "$seen" ] && break
  done
  kill "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  echo "$seen"
}
got=$(spin_of -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT)
[ "$got" = "GOMP_SPINCOUNT=1000 " ] && ok || bad "default wait policy: '$got'"
got=$(spin_of -u GOMP_SPINCOUNT OMP_WAIT_POLICY=active)
[ "$got" = "OMP_WAIT_POLICY=active " ] && ok || bad "user's OMP_WAIT_POLICY: '$got'"
rm -rf "$work/spin"

# output.at_steps: the steps do not depend on the output times, so two
# output intervals end in the same bytes (issue 35; ul-csph's punch, whose
# end state moves by a spacing when the steps land on the output times)
for e in 0.00001 0.00012; do
  "$sph" run punch_ul_csph --out "$work/at$e" --quiet --set output.png=false \
    --set output.at_steps=true --set output.every=$e \
    --set stability.zigzag_max=0 --set stability.fracture_dp=0 >/dev/null 2>&1
done
cmp -s "$work/at0.00001/punch_ul_csph_0048.vtp" \
  "$work/at0.00012/punch_ul_csph_0004.vtp" && ok ||
  bad "output.at_steps: the end states of two output intervals differ"
"$sph" check punch_ul_csph --set output.at_steps=3 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "at_steps" "$work/stderr" && ok ||
  bad "output.at_steps=3 not refused: $(cat "$work/stderr")"

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
