#!/usr/bin/env bash
# Bodies from particle files through the command (issue 34 item 4): a CSV
# of the built-in box's particles runs as the box, bit for bit; the .vtp a
# run writes at t = 0 read back gives the same run; a run continued from a
# deformed state's .vtp starts from its positions with no displacement;
# what sph check states; each bad file refused with exit 2 at the scene's
# file:line:col, naming the file (and the CSV's line), nothing written.
set -u
sph=$(realpath "$1")
with_mpi=${2:-0} # 1: sph is built with MPI (the .pvtp of a 2-rank run)
. "$(dirname "$0")/harness.sh"
mkdir -p "$work/case/parts"
cube_scene "$work/case/box.yaml" "{every: 0.002, fields: [pressure, velocity, displacement, von_mises, J, body_id, volume]}"
# the box's spacing, 1/6 as %.17g: the same dp, so the same kernel
sed 's|{box: {min: \[0, 0, 0\], max: \[1, 1, 1\]}}|{particles: {file: parts/box.csv}}|;
     s|particles: {count: \[5, 6, 7\]}|particles: {spacing: 0.16666666666666666}|' \
  "$work/case/box.yaml" >"$work/case/csv.yaml"
sed 's|parts/box.csv|parts/box.vtp|' "$work/case/csv.yaml" >"$work/case/vtp.yaml"
grep -q 'parts/box.csv' "$work/case/csv.yaml" || bad "the csv scene was not made"

# the values of an ASCII .vtp's array, on one line
array() { # FILE NAME
  awk -v name="Name=\"$2\"" 'found { print; exit } index($0, name) { found = 1 }' "$1"
}
"$sph" run "$work/case/box.yaml" --out "$work/box" --quiet >/dev/null 2>&1 &&
  "$sph" run "$work/case/box.yaml" --out "$work/ascii" --quiet \
    --set output.vtk.format=ascii >/dev/null 2>&1 || bad "box runs failed"
{
  echo "x, y, z, volume"
  paste -d, <(array "$work/ascii/cube_0000.vtp" Points | tr ' ' '\n' | paste -d, - - -) \
    <(array "$work/ascii/cube_0000.vtp" volume | tr ' ' '\n')
} >"$work/case/parts/box.csv"
[ "$(wc -l <"$work/case/parts/box.csv")" -eq 211 ] || bad "box.csv: $(head -3 "$work/case/parts/box.csv")"
cp "$work/box/cube_0000.vtp" "$work/case/parts/box.vtp"

# sph check from another folder: the file beside the scene, its statement
(cd / && "$sph" check "$work/case/csv.yaml") >"$work/out" 2>&1
[ $? -eq 0 ] && grep -qF "particles parts/box.csv: 210, total volume 1 m^3 (the file's); dp given" "$work/out" &&
  ok || bad "check: $(cat "$work/out")"
sed '/particles: {spacing/d' "$work/case/csv.yaml" >"$work/case/est.yaml"
"$sph" check "$work/case/est.yaml" >"$work/out" 2>&1
[ $? -eq 0 ] && grep -qF "dp = 0.1667 m" "$work/out" &&
  grep -qF "dp estimated: the median nearest-neighbour distance" "$work/out" && ok ||
  bad "estimated spacing: $(cat "$work/out")"

# the same run as the box, bit for bit, from the CSV and from the .vtp;
# the same summary (the verdict's indicators), timings apart
summary() { grep -vE '^ *"(sph|terms|sinks|wall_seconds|render_thread_seconds)"' "$1"; }
for kind in csv vtp; do
  "$sph" run "$work/case/$kind.yaml" --out "$work/$kind" --quiet >/dev/null 2>"$work/err" ||
    bad "$kind run: $(cat "$work/err")"
  for f in cube_0000.vtp cube_0002.vtp energy.csv; do
    cmp -s "$work/box/$f" "$work/$kind/$f" && ok || bad "$kind: $f differs from the box's"
  done
  [ "$(summary "$work/box/summary.json")" = "$(summary "$work/$kind/summary.json")" ] && ok ||
    bad "$kind: summary.json differs from the box's"
done
# a 2-rank run's .pvtp, its pieces placed by particle_id: the serial run
if [ "$with_mpi" = 1 ] && command -v mpirun >/dev/null; then
  mpi=(mpirun --oversubscribe --bind-to none -x OMP_NUM_THREADS=1 -np 2)
  [ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
  ids='s/body_id, volume\]/body_id, volume, particle_id]/'
  sed "$ids" "$work/case/box.yaml" >"$work/case/boxid.yaml"
  sed "$ids; s|parts/box.vtp|$work/r2/cube_0000.pvtp|" "$work/case/vtp.yaml" >"$work/case/pvtp.yaml"
  "${mpi[@]}" "$sph" run "$work/case/boxid.yaml" --threads 1 --out "$work/r2" --quiet >/dev/null 2>&1 &&
    "$sph" run "$work/case/boxid.yaml" --out "$work/boxid" --quiet >/dev/null 2>&1 &&
    "$sph" run "$work/case/pvtp.yaml" --out "$work/pvtp" --quiet >/dev/null 2>"$work/err" ||
    bad "pvtp runs: $(cat "$work/err")"
  for f in cube_0000.vtp cube_0002.vtp energy.csv; do
    cmp -s "$work/boxid/$f" "$work/pvtp/$f" && ok || bad "pvtp: $f differs from the box's"
  done
fi
(cd / && "$sph" check "$work/vtp/scene_used.yaml") >/dev/null 2>"$work/err" && ok ||
  bad "scene_used.yaml: $(cat "$work/err")"

# continued from the deformed state: its positions, stress-free
sed "s|parts/box.vtp|$work/ascii/cube_0002.vtp|" "$work/case/vtp.yaml" >"$work/case/more.yaml"
"$sph" run "$work/case/more.yaml" --out "$work/more" --quiet --set output.vtk.format=ascii \
  >/dev/null 2>"$work/err" || bad "continued run: $(cat "$work/err")"
[ "$(array "$work/more/cube_0000.vtp" Points)" = "$(array "$work/ascii/cube_0002.vtp" Points)" ] &&
  ok || bad "continued: the positions are not the deformed state's"
array "$work/more/cube_0000.vtp" displacement | tr ' ' '\n' | grep -qv '^0$' &&
  bad "continued: a displacement at t = 0" || ok
[ "$(array "$work/ascii/cube_0002.vtp" Points)" != "$(array "$work/ascii/cube_0000.vtp" Points)" ] &&
  ok || bad "the state at 0.004 s is not deformed"

# refused: exit 2 at the file key (line 9, column 25), nothing written
refuse() { # FILE EXPECTED [SCENE]
  sed "s|parts/box.csv|$1|" "$work/case/${3:-csv}.yaml" >"$work/case/bad.yaml"
  refused_run "$work/case/bad.yaml" "$work/case/bad.yaml:9:25" "$2" "$1"
}
csv() { # NAME LINES...
  local f=$work/case/parts/$1
  shift
  printf '%s\n' "$@" >"$f"
}
refuse parts/none.csv "parts/none.csv: no such file"
: >"$work/case/parts/empty.csv"
refuse parts/empty.csv "parts/empty.csv: the file is empty"
csv blank.csv "# only a comment" ""
refuse parts/blank.csv "parts/blank.csv: the file is empty"
csv header.csv "x, y, z" 
refuse parts/header.csv "parts/header.csv: no particles"
csv nan.csv "x, y, z" "0, 0, 0" "nan, 1, 1"
refuse parts/nan.csv "parts/nan.csv:3: column 'x' is nan"
csv inf.csv "x, y, z" "0, 0, 0" "1, 1, inf"
refuse parts/inf.csv "parts/inf.csv:3: column 'z' is inf"
csv word.csv "x, y, z" "0, 0, one"
refuse parts/word.csv "parts/word.csv:2: column 'z': not a number"
csv short.csv "x, y, z, volume" "0, 0, 0, 1" "1, 1, 1"
refuse parts/short.csv "parts/short.csv:3: 3 values, the header names 4 columns"
csv negative.csv "x, y, z, volume" "0, 0, 0, 1" "1, 1, 1, -0.5"
refuse parts/negative.csv "parts/negative.csv:3: column 'volume' is -0.5: volumes must be positive"
csv zero.csv "x, y, z, volume" "0, 0, 0, 0"
refuse parts/zero.csv "parts/zero.csv:2: column 'volume' is 0: volumes must be positive"
csv noy.csv "x, z" "0, 0" "1, 1"
refuse parts/noy.csv "parts/noy.csv:1: no column 'y' in the header"
csv numbers.csv "0, 0, 0" "1, 1, 1"
refuse parts/numbers.csv "parts/numbers.csv:1: the first line must name the columns"
csv twice.csv "x, y, z" "0, 0, 1" "1, 0, 1" "0, 1, 1" "1, 0, 1"
refuse parts/twice.csv "parts/twice.csv: two particles at one position (1, 0, 1): line 3 and line 5"
csv flat.csv "x, y" "0, 0" "1, 0"
refuse parts/flat.csv "parts/flat.csv: a 2D file (no column 'z') for a 3D body"
csv flatz.csv "x, y, z" "0, 0, 0" "1, 0, 0"
refuse parts/flatz.csv "parts/flatz.csv: a 2D file (every z is 0) for a 3D body"
refuse parts/box.stl "parts/box.stl: a particle file is a .csv or a .vtp"
sed 's/NumberOfPoints="210"/NumberOfPoints="0"/' "$work/ascii/cube_0000.vtp" >"$work/case/parts/empty.vtp"
refuse parts/empty.vtp "parts/empty.vtp: no points"
csv one.csv "x, y, z" "0.5, 0.5, 0.5"
sed 's|parts/box.csv|parts/one.csv|' "$work/case/est.yaml" >"$work/case/bad.yaml"
"$sph" check "$work/case/bad.yaml" >/dev/null 2>"$work/err"
[ $? -eq 2 ] && grep -qF "bad.yaml:9:5" "$work/err" &&
  grep -qF "parts/one.csv holds one particle: its spacing cannot be estimated" "$work/err" && ok ||
  bad "one particle: $(cat "$work/err")"
awk 'done != 1 && seen { sub(/^[^ ]+/, "-1"); done = 1 } /Name="volume"/ { seen = 1 } 1' \
  "$work/ascii/cube_0000.vtp" >"$work/case/parts/neg.vtp"
refuse parts/neg.vtp "parts/neg.vtp: point 0: volume is -1: volumes must be positive"
# a 3D file for a 2D body
sed 's/^dimension: 3/dimension: 2/; s/{count: \[5, 6, 7\]}/{count: [5, 6]}/;
     /initial_velocity/d' \
  "$work/case/csv.yaml" >"$work/case/flat.yaml"
refuse parts/box.csv "parts/box.csv: a 3D file (z is 0.166667 at line 3) for a 2D body" flat
# a 2D body from x, y: 7 x 7 particles 1/6 apart, dp^2 each
awk 'BEGIN { print "x, y"; for (i = 0; i < 7; ++i) for (j = 0; j < 7; ++j) print i / 6 ", " j / 6 }' \
  >"$work/case/parts/plane.csv"
sed 's|parts/box.csv|parts/plane.csv|' "$work/case/flat.yaml" >"$work/case/plane.yaml"
"$sph" check "$work/case/plane.yaml" >"$work/out" 2>&1 &&
  grep -qF "particles parts/plane.csv: 49, total volume 1.36111 m^2 (dp^d each)" "$work/out" && ok ||
  bad "2D csv: $(cat "$work/out")"

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
