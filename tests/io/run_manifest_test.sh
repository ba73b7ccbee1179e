#!/usr/bin/env bash
# The output folder's manifest (issue 36 item 4): a run writes
# DIR/.sph.manifest (the files it may write, then those it wrote with their
# sizes); --overwrite removes only those, and a file under a name sph would
# write that no run of sph wrote there (or that changed since) is refused,
# named, with exit 2 before anything is written.
set -u
sph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
args=(--threads 1 --quiet --set time.end=0.01 --set output.png=false)
scene=spinning_cube

# a plain run into a folder with the user's energy.csv / probes.csv: refused
for f in energy.csv probes.csv spinning_cube_0003.vtp summary.json.part; do
  out=$work/user_$f
  mkdir -p "$out"
  echo precious >"$out/$f"
  for extra in "" --overwrite; do
    "$sph" run "$scene" --out "$out" $extra "${args[@]}" >"$work/log" 2>&1
    rc=$?
    [ $rc -eq 2 ] && grep -qF "$out/$f is not a file an earlier sph run wrote" "$work/log" ||
      fail "$f ${extra:-plain}: exit $rc: $(cat "$work/log")"
    [ "$(cat "$out/$f")" = precious ] || fail "$f ${extra:-plain}: the user's file was replaced"
    [ "$(ls "$out")" = "$f" ] || fail "$f ${extra:-plain}: files written: $(ls "$out")"
  done
done

# --overwrite removes the earlier run's files only, the user's stay
out=$work/a
"$sph" run "$scene" --out "$out" "${args[@]}" >/dev/null || fail "first run"
[ -f "$out/.sph.manifest" ] && grep -q "^[0-9]* energy.csv$" "$out/.sph.manifest" ||
  fail "no manifest with sizes: $(cat "$out/.sph.manifest")"
echo mine >"$out/notes.txt"
mkdir -p "$out/frames" && echo mine >"$out/frames/spinning_cube_0042.png.bak"
"$sph" run "$scene" --out "$out" --overwrite "${args[@]}" --set time.end=0.004 >/dev/null ||
  fail "--overwrite of sph's own files"
[ -f "$out/notes.txt" ] && [ -f "$out/frames/spinning_cube_0042.png.bak" ] || fail "--overwrite removed the user's files"
[ -f "$out/spinning_cube_0004.vtp" ] && fail "--overwrite left the earlier run's frame 4"
# a file sph wrote but the user changed since: refused
echo more >>"$out/energy.csv"
"$sph" run "$scene" --out "$out" --overwrite "${args[@]}" >"$work/log" 2>&1
[ $? -eq 2 ] && grep -qF "$out/energy.csv changed since sph wrote it" "$work/log" ||
  fail "changed file: $(cat "$work/log")"
grep -q "^more$" "$out/energy.csv" || fail "the changed energy.csv was replaced"
# a crafted manifest names nothing outside the folder
out=$work/crafted
mkdir -p "$out" "$work/victim"
echo precious >"$work/victim/energy.csv"
printf '9 ../victim/energy.csv\n9 /etc/hostname\n' >"$out/.sph.manifest"
"$sph" run "$scene" --out "$out" --overwrite "${args[@]}" >/dev/null 2>&1 || fail "run over a crafted manifest"
[ -f "$work/victim/energy.csv" ] || fail "a crafted manifest removed a file outside the folder"
# a manifest that is a link is not followed
out=$work/linked
mkdir -p "$out"
echo precious >"$work/target"
ln -s "$work/target" "$out/.sph.manifest"
"$sph" run "$scene" --out "$out" "${args[@]}" >/dev/null 2>&1
[ "$(cat "$work/target")" = precious ] || fail "the manifest link's target was written"

echo "$fails failures"
[ $fails -eq 0 ]
