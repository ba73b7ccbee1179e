#!/usr/bin/env bash
# sph render: the frames drawn again from a run's .vtp files equal the
# frames `sph run` drew with the same options (byte for byte); --range
# global and --field work; a missing or damaged .vtp, a field the files do
# not hold and a folder without a run exit 2 naming the file.
set -u
sph=$1
src=$2
. "$(dirname "$0")/harness.sh"

run=$work/run
"$sph" run "$src/scenes/twisting_column.yaml" --out "$run" --quiet --threads 1 \
  --set 'bodies.0.particles.count=[3,13,3]' --set time.end=0.02 \
  --set output.png.width=320 --set output.png.height=240 >/dev/null 2>&1 ||
  bad "sph run failed"
"$sph" render "$run" --out "$work/again" >"$work/stdout" 2>&1
rc=$?
same=0
for f in "$run"/frames/*.png; do
  cmp -s "$f" "$work/again/frames/$(basename "$f")" && same=$((same + 1))
done
n=$(ls "$run"/frames/*.png | wc -l)
if [ $rc -eq 0 ] && [ "$n" -eq 5 ] && [ $same -eq "$n" ]; then ok; else
  bad "re-render (exit $rc): $same of $n frames identical: $(cat "$work/stdout")"
fi
"$sph" imgdiff "$run/frames/twisting_column_0004.png" \
  "$work/again/frames/twisting_column_0004.png" >/dev/null && ok || bad "imgdiff of a re-drawn frame"
# the run's .pvd named directly, another field over every frame's range
"$sph" render "$run/twisting_column.pvd" --out "$work/vm" --field von_mises \
  --range global --width 160 --height 120 >"$work/stdout" 2>&1
[ $? -eq 0 ] && [ "$(ls "$work/vm/frames" | wc -l)" -eq 5 ] && ok ||
  bad "von Mises, global range: $(cat "$work/stdout")"
# a field the files do not hold
"$sph" render "$run" --out "$work/x" --field density 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "twisting_column_0000.vtp: no point array 'density' (it has: pressure" "$work/stderr" && ok ||
  bad "missing array: $(cat "$work/stderr")"
# an output folder that cannot be made or written in (issue 21 item 13)
touch "$work/plain"
for out in "$work/plain/frames" /proc; do
  "$sph" render "$run" --out "$out" 2>"$work/stderr" >/dev/null
  [ $? -eq 2 ] && grep -qE "cannot (create|write in) the output folder $out: " "$work/stderr" && ok ||
    bad "unwritable --out $out: $(cat "$work/stderr")"
done
# a damaged file (cut short) and a missing one
head -c 2000 "$run/twisting_column_0003.vtp" >"$work/cut.vtp"
mv "$work/cut.vtp" "$run/twisting_column_0003.vtp"
"$sph" render "$run" --out "$work/y" 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "twisting_column_0003.vtp" "$work/stderr" && ok ||
  bad "damaged .vtp: $(cat "$work/stderr")"
rm "$run/twisting_column_0003.vtp"
"$sph" render "$run" --out "$work/z" 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "twisting_column_0003.vtp: cannot open" "$work/stderr" && ok ||
  bad "missing .vtp: $(cat "$work/stderr")"
# not a run folder; no operand
"$sph" render "$work" 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "scene_used.yaml" "$work/stderr" && ok || bad "not a run: $(cat "$work/stderr")"
"$sph" render 2>/dev/null >/dev/null
[ $? -eq 2 ] && ok || bad "no operand"
"$sph" render --help | grep -q "usage: sph render" && ok || bad "--help"
echo "render cli: $pass passed, $fail failed"
[ $fail -eq 0 ]
