#!/usr/bin/env bash
# The command as users expect it: --version, help for every command, a
# shipped scene by name, distinct exit codes (0 stable, 1 unstable, 2 bad
# input or usage, 3 I/O), --out=DIR and output.png=true.
set -u
sph=$1
src=$2
. "$(dirname "$0")/harness.sh"

# a 3 x 7 x 3 column for 0.02 s (as in run_cli_tests.sh)
tiny="$work/tiny.yaml"
sed -e 's/count: \[7, 37, 7\]/count: [3, 7, 3]/' -e 's/end: 0.3/end: 0.02/' \
  -e 's/^stability: .*/stability: {fracture_dp: 3, zigzag_max: 0}/' \
  "$src/scenes/twisting_column.yaml" >"$tiny"
quick=(--quiet --set output.png=false --set output.vtk=false)

# --version: the project version and a commit (or "unknown"); both, and the
# command line, land in summary.json and scene_used.yaml
version=$(sed -n 's/^project(sph VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")
"$sph" --version >"$work/stdout" 2>&1
rc=$?
[ $rc -eq 0 ] && grep -qE "^sph $version \(commit [0-9a-zA-Z.-]+\)$" "$work/stdout" && ok ||
  bad "--version (exit $rc): $(cat "$work/stdout")"
"$sph" run "$tiny" --out "$work/v" "${quick[@]}" >/dev/null 2>&1
python3 - "$work/v/summary.json" "$version" "$sph run $tiny --out $work/v ${quick[*]}" <<'PY' && ok || bad "summary.json provenance"
import json, sys
s = json.load(open(sys.argv[1]))["sph"]
assert s["version"] == sys.argv[2] and s["commit"], s
assert s["command"] == sys.argv[3], (s["command"], sys.argv[3])
PY
head -2 "$work/v/scene_used.yaml" | grep -qF "sph $version (commit" &&
  head -2 "$work/v/scene_used.yaml" | grep -qF "# command: $sph run $tiny" && ok ||
  bad "scene_used.yaml provenance: $(head -2 "$work/v/scene_used.yaml")"

# help: bare sph, sph help [CMD], CMD --help and CMD -h print the usage on
# stdout and exit 0, whatever else is on the line
"$sph" >"$work/stdout" 2>&1
[ $? -eq 0 ] && grep -q '^usage: sph <command>' "$work/stdout" && ok || bad "bare sph: $(cat "$work/stdout")"
for cmd in run check study list imgdiff bench; do
  for h in --help -h; do
    "$sph" $cmd $h >"$work/stdout" 2>"$work/stderr"
    rc=$?
    [ $rc -eq 0 ] && grep -q "^usage: sph $cmd" "$work/stdout" && [ ! -s "$work/stderr" ] && ok ||
      bad "sph $cmd $h (exit $rc): $(cat "$work/stdout" "$work/stderr")"
  done
  "$sph" help $cmd | grep -q "^usage: sph $cmd" && ok || bad "sph help $cmd"
done
"$sph" run "$tiny" --out "$work/h" -h >/dev/null 2>&1 && [ ! -e "$work/h" ] && ok || bad "run SCENE -h ran"
"$sph" run --set time.end=1 --frobnicate 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "unknown option --frobnicate" "$work/stderr" && ok || bad "unknown option: $(cat "$work/stderr")"
"$sph" list extra 2>/dev/null
[ $? -eq 2 ] && ok || bad "list with an operand"

# --opt=VALUE as well as --opt VALUE
"$sph" run "$tiny" --out="$work/eq" --set=time.end=0.01 "${quick[@]}" >/dev/null 2>&1 &&
  [ -f "$work/eq/summary.json" ] && grep -q '"end": 0.01\|end: 0.01' "$work/eq/scene_used.yaml" && ok ||
  bad "--out=DIR --set=k=v: $(ls "$work" 2>&1)"
"$sph" study "$tiny" --vary=time.end=0.01,0.02 --dry-run >"$work/stdout" 2>&1 &&
  grep -q "2 cases valid" "$work/stdout" && ok || bad "study --vary=: $(cat "$work/stdout")"

# a shipped scene by name; an existing path wins; an unknown name lists the
# shipped ones
"$sph" check punch >"$work/stdout" 2>&1 && grep -qF "($src/scenes/punch.yaml)" "$work/stdout" && ok ||
  bad "check punch: $(cat "$work/stdout")"
"$sph" study punch --vary time.end=0.001 --dry-run >/dev/null 2>&1 && ok || bad "study punch"
(cd "$work" && cp "$tiny" punch.yaml && "$sph" check punch.yaml) >"$work/stdout" 2>&1 &&
  grep -qF "(punch.yaml)" "$work/stdout" && ok || bad "a local punch.yaml: $(cat "$work/stdout")"
"$sph" run no_such_scene >/dev/null 2>"$work/stderr"
[ $? -eq 2 ] && grep -qF "no_such_scene" "$work/stderr" && grep -qE "shipped scenes:.* punch .*twisting_column" "$work/stderr" &&
  [ ! -e outputs/no_such_scene ] && ok || bad "unknown scene name: $(cat "$work/stderr")"

# exit codes, each provoked: 0 stable, 1 unstable, 2 bad input, 3 I/O
"$sph" run "$tiny" --out "$work/e0" "${quick[@]}" >/dev/null 2>&1
rc=$?
[ $rc -eq 0 ] && ok || bad "stable run: exit $rc"
"$sph" run "$tiny" --out "$work/e1" "${quick[@]}" --set method.cfl=1.5 --set time.end=0.2 \
  --set output.every=0.05 >"$work/stdout" 2>&1
rc=$?
[ $rc -eq 1 ] && grep -q "^verdict: UNSTABLE" "$work/stdout" && ok || bad "unstable run: exit $rc: $(cat "$work/stdout")"
"$sph" run "$tiny" --out "$work/e2" "${quick[@]}" --set materials.rubber.density=-1 >/dev/null 2>&1
rc=$?
[ $rc -eq 2 ] && [ ! -e "$work/e2" ] && ok || bad "bad input: exit $rc"
touch "$work/plain"
# an output folder that cannot be made or written in is bad input, exit 2
# naming it, whether it exists or not (issue 21 item 13; it was 1 or 2,
# then 3); permissions do not stop root (CI), so a file in the path and
# /proc (nothing can be made in it) stand in for them, and a folder
# without write permission is tried when not root
unwritable() { # message, folder, command...
  local msg=$1 dir=$2
  shift 2
  "$@" >/dev/null 2>"$work/stderr"
  local rc=$?
  [ $rc -eq 2 ] && grep -qF "sph: $msg $dir: " "$work/stderr" && ok ||
    bad "unwritable $dir ($*): exit $rc: $(cat "$work/stderr")"
}
made="cannot create the output folder"
written="cannot write in the output folder"
unwritable "$made" "$work/plain" "$sph" run "$tiny" --out "$work/plain" "${quick[@]}"
unwritable "$made" "$work/plain/sub" "$sph" run "$tiny" --out "$work/plain/sub" "${quick[@]}"
unwritable "$made" /proc/sph-no-such "$sph" run "$tiny" --out /proc/sph-no-such "${quick[@]}"
unwritable "$written" /proc "$sph" run "$tiny" --out /proc --overwrite "${quick[@]}"
unwritable "$written" /proc "$sph" study "$tiny" --vary time.end=0.01,0.02 --out /proc
unwritable "$made" "$work/plain/r" "$sph" study "$tiny" --vary time.end=0.01,0.02 --out "$work/plain/r"
if [ "$(id -u)" -ne 0 ]; then
  mkdir -p "$work/ro" && chmod 555 "$work/ro"
  unwritable "$written" "$work/ro" "$sph" run "$tiny" --out "$work/ro" "${quick[@]}"
  unwritable "$made" "$work/ro/sub" "$sph" run "$tiny" --out "$work/ro/sub" "${quick[@]}"
  chmod 755 "$work/ro"
fi
[ ! -e /proc/sph-no-such ] && [ -f "$work/plain" ] && [ ! -s "$work/plain" ] && ok ||
  bad "an unwritable output folder: something was written"
# a write failing mid-run (file size limit as a full disk): energy.csv
# outgrows 4 KiB after about 15 rows
(trap '' XFSZ; ulimit -f 4; "$sph" run "$tiny" --out "$work/e3" "${quick[@]}" \
  --set time.end=0.3 >/dev/null 2>"$work/stderr")
rc=$?
[ $rc -eq 3 ] && grep -qF "$work/e3/" "$work/stderr" && ok || bad "write failure: exit $rc: $(cat "$work/stderr")"

# output.png=true: frames with the defaults; anything but a mapping or a
# boolean refused naming the key
"$sph" run "$tiny" --out "$work/pngtrue" --quiet --set output.png=true >/dev/null 2>&1
[ $? -eq 0 ] && ls "$work/pngtrue/frames/"*_0000.png >/dev/null 2>&1 &&
  "$sph" check "$work/pngtrue/scene_used.yaml" >/dev/null 2>&1 && ok || bad "output.png=true"
"$sph" check "$tiny" --set output.png=maybe 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -qF "output.png: expected a mapping, true or false" "$work/stderr" && ok ||
  bad "output.png=maybe: $(cat "$work/stderr")"

# one run per output folder: a second run into a busy folder is refused
# naming the running one's pid (issue 21 item 6)
"$sph" run "$src/scenes/twisting_column.yaml" --out "$work/busy" --quiet --threads 1 \
  --set time.end=30 --set output.png=false >/dev/null 2>&1 &
first=$!
for _ in $(seq 200); do
  [ -s "$work/busy/.sph.lock" ] && [ -f "$work/busy/scene_used.yaml" ] && break
  sleep 0.02
done
"$sph" run "$src/scenes/twisting_column.yaml" --out "$work/busy" --quiet --overwrite \
  --set time.end=0.01 >/dev/null 2>"$work/stderr"
rc=$?
kill -TERM $first
wait $first
[ $rc -eq 2 ] && grep -qF "$work/busy is in use by another sph run (pid $first)" "$work/stderr" &&
  [ -f "$work/busy/scene_used.yaml" ] && ok || bad "busy folder: exit $rc: $(cat "$work/stderr")"
"$sph" run "$src/scenes/twisting_column.yaml" --out "$work/busy" --quiet --overwrite \
  --set 'bodies.0.particles.count=[3,7,3]' --set time.end=0.01 --set output.png=false >/dev/null 2>&1 &&
  ok || bad "the folder is not free after the first run ended"

# --overwrite removes what the earlier run wrote, never the user's files
# (issue 21 item 3), even under a name of the kind sph writes that no run
# wrote here (twisting_column_0099.vtp.part: not in the folder's manifest,
# issue 36 item 4)
ow=$work/ow
"$sph" run "$tiny" --out "$ow" --quiet --set output.png=true >/dev/null 2>&1
mkdir -p "$ow/frames"
touch "$ow/notes.vtp" "$ow/mesh.pvd" "$ow/other_0001.vtp" "$ow/frames/photo.png" \
  "$ow/twisting_column_0099.vtp.part"
"$sph" run "$tiny" --out "$ow" --quiet --overwrite --set 'output.fields=[pressure]' \
  --set time.end=0.01 >/dev/null 2>&1
if [ -f "$ow/notes.vtp" ] && [ -f "$ow/mesh.pvd" ] && [ -f "$ow/other_0001.vtp" ] &&
  [ -f "$ow/frames/photo.png" ] && [ -f "$ow/twisting_column_0099.vtp.part" ] &&
  [ ! -e "$ow/twisting_column_0004.vtp" ] && [ ! -e "$ow/frames/twisting_column_0004.png" ] &&
  [ -f "$ow/twisting_column_0002.vtp" ]; then ok; else
  bad "--overwrite: $(ls "$ow" "$ow/frames")"
fi

# a path too long for the run's files: refused before anything is written
long=$work/$(printf 'd%.0s' $(seq 950))
"$sph" run "$tiny" --out "$long" --quiet 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "at most 900" "$work/stderr" && [ ! -e "$long" ] && ok ||
  bad "long --out: $(cat "$work/stderr")"
# past a file-size limit (no trap of SIGXFSZ here): a clean I/O error,
# exit 3, no temporary file left (issue 21 item 5)
(
  ulimit -f 8
  "$sph" run "$src/scenes/twisting_column.yaml" --out "$work/fsize" --quiet \
    --set 'bodies.0.particles.count=[3,7,3]' --set output.png=false \
    --set time.end=0.3 >/dev/null 2>"$work/stderr"
)
rc=$?
[ $rc -eq 3 ] && grep -q "File too large" "$work/stderr" &&
  ! ls "$work/fsize" | grep -q '\.part$' && ok || bad "file-size limit: exit $rc: $(cat "$work/stderr")"

# a run that cannot fit in memory: refused before allocating, not killed
# by the kernel (issue 21 item 2)
"$sph" check "$src/scenes/twisting_column.yaml" \
  --set 'bodies.0.particles.count=[300,300,300]' 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "GB of memory is available" "$work/stderr" && ok ||
  bad "oversized run: $(cat "$work/stderr")"
# or above --max-memory: the punch (693 particles) needs about 2 MB
"$sph" check punch --max-memory 1M 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "the limit (--max-memory) is 0.001 GB" "$work/stderr" && ok ||
  bad "--max-memory 1M: $(cat "$work/stderr")"
"$sph" run punch --max-memory 1M --out "$work/mm" 2>/dev/null >/dev/null
[ $? -eq 2 ] && [ ! -e "$work/mm" ] && ok || bad "run --max-memory 1M"
"$sph" check punch --max-memory 5M >/dev/null 2>&1 && ok || bad "--max-memory 5M"
"$sph" check punch --max-memory 5X 2>"$work/stderr" >/dev/null
[ $? -eq 2 ] && grep -q "max-memory takes a size" "$work/stderr" && ok || bad "--max-memory 5X"

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
