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
sed -e 's/count: \[5, 25, 5\]/count: [3, 7, 3]/' -e 's/end: 0.3/end: 0.02/' \
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

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
