#!/usr/bin/env bash
# sph study: a tiny swinging-cube study (2 methods x 2 resolutions) gives
# results.csv rows and columns, report.md with fitted orders and the gnuplot
# figures; bracketed values split only on top-level commas; unstable runs
# stay rows; a bad --vary stops before anything is written (exit 2, key
# named); --resume reruns only the case whose row was deleted; a period
# reference fills the period columns.
set -u
sph=$1
src=$2
. "$(dirname "$0")/harness.sh"
check() { if eval "$2"; then ok; else bad "$1"; fi; }
scene=$src/scenes/swinging_cube.yaml
short=(--set time.end=0.002 --threads 1)

# columns of row $2 (1 = header) of CSV $1, quotes honoured
ncols() { python3 -c 'import csv,sys; r=list(csv.reader(open(sys.argv[1]))); print(len(r[int(sys.argv[2])-1]))' "$1" "$2"; }
field() { python3 -c 'import csv,sys; r=list(csv.DictReader(open(sys.argv[1]))); print(r[int(sys.argv[2])][sys.argv[3]])' "$1" "$2" "$3"; }

# --- the tiny study
out=$work/study
"$sph" study "$scene" "${short[@]}" --vary method.fields=pF,pFJ \
  --vary bodies.0.particles.spacing=0.25,0.125 --out "$out" \
  >"$work/stdout" 2>"$work/stderr"
rc=$?
check "study exit $rc: $(cat "$work/stderr")" '[ $rc -eq 0 ]'
csv=$out/results.csv
check "results.csv has a header and 4 rows" '[ "$(wc -l <"$csv")" -eq 5 ]'
check "18 columns" '[ "$(ncols "$csv" 1)" -eq 18 ] && [ "$(ncols "$csv" 5)" -eq 18 ]'
check "header" 'head -1 "$csv" | grep -q "^method.fields,bodies.0.particles.spacing,particles,dp,steps,wall_seconds,particle_steps_per_second,l2_velocity,l2_stress,l2_displacement,h1_displacement,period_error,period,energy_drift,linear_momentum_drift,angular_momentum_drift,stable,reason$"'
check "rows in case order" '[ "$(cut -d, -f1,2 "$csv" | tail -4 | tr "\n" " ")" = "pF,0.25 pF,0.125 pFJ,0.25 pFJ,0.125 " ]'
check "particles 64 and 512" '[ "$(field "$csv" 0 particles)" = 64 ] && [ "$(field "$csv" 1 particles)" = 512 ]'
check "l2_velocity filled" 'python3 -c "import sys; assert 0 < float(sys.argv[1]) < 1" "$(field "$csv" 1 l2_velocity)"'
check "stable true" '[ "$(field "$csv" 3 stable)" = true ]'
check "progress lines" 'grep -q "^\[1/4\] method.fields=pF bodies.0.particles.spacing=0.25: .* s, stable, l2_velocity .* about .* s left$" "$work/stdout" && grep -q "^\[4/4\] method.fields=pFJ" "$work/stdout"'
check "runs wrote no vtk" '[ -f "$out/runs/001/summary.json" ] && ! ls "$out"/runs/*/*.vtp >/dev/null 2>&1'
check "report.md with orders" 'grep -qE "^\| method.fields=pF \| 2 \| [12]\.[0-9]+ \|" "$out/report.md" && grep -q "^| method.fields=pFJ | 2 |" "$out/report.md"'
if command -v gnuplot >/dev/null; then
  check "png figures" 'head -c 8 "$out/convergence.png" | od -c | grep -q "P   N   G" && [ -s "$out/error_vs_time.png" ] && ! ls "$out"/*.part >/dev/null 2>&1'
else
  check "plots skipped notice" 'grep -q "^plots skipped: gnuplot not found$" "$work/stdout"'
fi
# without gnuplot on PATH the figures are skipped with a notice
check "no gnuplot" 'PATH=/nonexistent "$sph" study "$scene" "${short[@]}" --vary method.fields=pF --vary bodies.0.particles.spacing=0.25 --out "$work/nogp" | grep -q "^plots skipped: gnuplot not found$" && [ ! -e "$work/nogp/convergence.png" ]'

# --- the same folder again: refused without --resume
"$sph" study "$scene" "${short[@]}" --vary method.fields=pF,pFJ \
  --vary bodies.0.particles.spacing=0.25,0.125 --out "$out" >/dev/null 2>"$work/stderr"
rc=$?
check "second study refused (exit $rc)" '[ $rc -eq 2 ] && grep -q "resume" "$work/stderr"'

# --- --resume after deleting one row reruns only that case
sed -i '/^pFJ,0.25,/d' "$csv"
touch -d '2000-01-01' "$out"/runs/*/summary.json
"$sph" study "$scene" "${short[@]}" --vary method.fields=pF,pFJ \
  --vary bodies.0.particles.spacing=0.25,0.125 --out "$out" --resume \
  >"$work/stdout" 2>"$work/stderr"
rc=$?
check "resume exit $rc: $(cat "$work/stderr")" '[ $rc -eq 0 ]'
check "one case run" 'grep -q "4 cases (1 to run" "$work/stdout" && [ "$(grep -c "^\[" "$work/stdout")" -eq 1 ] && grep -q "^\[4/4\] method.fields=pFJ bodies.0.particles.spacing=0.25:" "$work/stdout"'
check "only run 003 rewritten" '[ -n "$(find "$out/runs/003/summary.json" -newermt 2001-01-01)" ] && [ -z "$(find "$out"/runs/00[124]/summary.json -newermt 2001-01-01)" ]'
check "4 rows again" '[ "$(wc -l <"$csv")" -eq 5 ] && grep -q "^pFJ,0.25," "$csv"'

# --- a study killed (SIGKILL, the whole process group) after its first row
# keeps that row; --resume runs only the others
out3=$work/killed
kill_args=(study "$scene" --set time.end=0.004 --threads 1 --vary
  bodies.0.particles.spacing=0.25,0.0625,0.05 --out "$out3")
setsid "$sph" "${kill_args[@]}" >"$work/kstdout" 2>&1 &
pid=$!
for _ in $(seq 600); do
  [ "$(wc -l 2>/dev/null <"$out3/results.csv" || echo 0)" -ge 2 ] && break
  sleep 0.05
done
kill -9 -- -"$pid" 2>/dev/null
wait "$pid" 2>/dev/null
rows=$(($(wc -l <"$out3/results.csv") - 1))
echo "killed study: $rows row(s) kept"
check "killed study kept $rows row(s), 1 or 2 expected" '[ "$rows" -ge 1 ] && [ "$rows" -le 2 ] && ! grep -q "^\[3/3\]" "$work/kstdout"'
"$sph" "${kill_args[@]}" --resume >"$work/stdout" 2>"$work/stderr"
rc=$?
check "resume after kill exit $rc: $(cat "$work/stderr")" '[ $rc -eq 0 ]'
check "resume ran $((3 - rows)) case(s)" 'grep -q "3 cases ($((3 - rows)) to run" "$work/stdout" && [ "$(grep -c "^\[" "$work/stdout")" -eq $((3 - rows)) ]'
check "3 rows after resume" '[ "$(wc -l <"$out3/results.csv")" -eq 4 ] && [ "$(cut -d, -f1 "$out3/results.csv" | tail -3 | sort -g | tr "\n" " ")" = "0.05 0.0625 0.25 " ]'

# --- bracketed values; unstable runs stay rows (a fracture threshold of
# 1.01 dp trips on any stretch)
out2=$work/brackets
"$sph" study "$scene" "${short[@]}" --set 'bodies.0.particles={count: [3,3,3]}' \
  --set stability.fracture_dp=1.01 --vary 'bodies.0.particles.count=[3,3,3],[5,5,5]' --out "$out2" \
  >"$work/stdout" 2>"$work/stderr"
rc=$?
check "bracket study exit $rc: $(cat "$work/stderr")" '[ $rc -eq 0 ]'
check "values split on top-level commas" '[ "$(field "$out2/results.csv" 0 bodies.0.particles.count)" = "[3,3,3]" ] && [ "$(field "$out2/results.csv" 1 dp)" = 0.25 ]'
check "unstable row kept" '[ "$(field "$out2/results.csv" 0 stable)" = false ] && [ -n "$(field "$out2/results.csv" 0 reason)" ] && grep -q "UNSTABLE" "$work/stdout"'

# --- bad --vary: exit 2, key named, no folder
for v in method.bogus=1,2 method.fields=pF,pXX bodies.0.particles.spacing=0.25,-1; do
  key=${v%%=*}
  dir=$work/bad_$key
  "$sph" study "$scene" "${short[@]}" --vary "$v" --out "$dir" >"$work/stdout" 2>"$work/stderr"
  rc=$?
  check "--vary $v: exit $rc, 2 expected" '[ $rc -eq 2 ]'
  check "--vary $v names $key: $(cat "$work/stderr")" 'grep -q "$key" "$work/stderr"'
  check "--vary $v wrote nothing" '[ ! -e "$dir" ] && [ ! -s "$work/stdout" ]'
done
"$sph" study "$scene" --vary 'method.fields=[pF' --out "$work/bad_b" >/dev/null 2>"$work/stderr"
rc=$?
check "unbalanced bracket refused" '[ $rc -eq 2 ] && grep -q unbalanced "$work/stderr" && [ ! -e "$work/bad_b" ]'
"$sph" study "$scene" --out "$work/bad_c" >/dev/null 2>"$work/stderr"
rc=$?
check "no --vary: usage" '[ $rc -eq 2 ] && grep -q "usage: sph study" "$work/stderr"'
"$sph" study "$scene" --vary method.fields=pF --resolution method.cfl --out "$work/bad_d" >/dev/null 2>"$work/stderr"
rc=$?
check "--resolution not varied" '[ $rc -eq 2 ] && grep -q "method.cfl" "$work/stderr"'

"$sph" study "$scene" --vary method.fields=pF --repeat 0 --out "$work/bad_e" >/dev/null 2>"$work/stderr"
rc=$?
check "--repeat 0 refused" '[ $rc -eq 2 ] && grep -q "repeat" "$work/stderr" && [ ! -e "$work/bad_e" ]'

# --- a period reference: the 2D plate's first period at H/dp 5
"$sph" study "$src/scenes/oscillating_plate_2d.yaml" --threads 1 \
  --set time.end=0.3 --vary bodies.0.particles.spacing=0.004 \
  --out "$work/per" >"$work/stdout" 2>"$work/stderr"
rc=$?
check "period study exit $rc: $(cat "$work/stderr")" '[ $rc -eq 0 ]'
check "period and its error filled" 'python3 -c "import sys; p, e = float(sys.argv[1]), float(sys.argv[2]); assert 0.2 < p < 0.35 and abs(e - abs(p - 0.254) / 0.254) < 1e-5" "$(field "$work/per/results.csv" 0 period)" "$(field "$work/per/results.csv" 0 period_error)"'
check "report.md period column, no L2 columns" 'grep -q "| period_error | period |" "$work/per/report.md" && ! grep -q "l2_velocity" "$work/per/report.md"'

# --- --repeat: one row, wall time the median of the repeats
"$sph" study "$scene" "${short[@]}" --vary bodies.0.particles.spacing=0.25 --repeat 3 --out "$work/rep" >"$work/stdout" 2>&1
rc=$?
check "--repeat 3 (exit $rc)" '[ $rc -eq 0 ] && [ "$(wc -l <"$work/rep/results.csv")" -eq 2 ] && grep -q "median of 3 repeats" "$work/rep/report.md"'

# --- the shipped studies are valid (--dry-run: validated, listed, not run)
for f in "$src"/studies/*.sh; do
  SPH=$sph "$f" --dry-run --out "$work/dry" >"$work/stdout" 2>"$work/stderr"
  rc=$?
  check "$(basename "$f") --dry-run (exit $rc): $(cat "$work/stderr")" '[ $rc -eq 0 ] && grep -q "valid, nothing run" "$work/stdout" && [ ! -e "$work/dry" ]'
done

echo "study tests: $pass passed, $fail failed"
[ $fail -eq 0 ]
