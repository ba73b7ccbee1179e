#!/usr/bin/env bash
# cmake --install into a temporary prefix: the binary, the man page, the
# completion, the scenes and studies land in place, and the installed sph
# runs an installed scene by name from another folder (no source tree).
set -u
build=$1
. "$(dirname "$0")/harness.sh"
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >"$work/log" 2>&1 || bad "install: $(cat "$work/log")"
for f in bin/sph share/man/man1/sph.1 share/bash-completion/completions/sph \
  share/sph/scenes/twisting_column.yaml share/sph/studies/swinging_cube.sh; do
  [ -e "$prefix/$f" ] && ok || bad "not installed: $f"
done
mkdir -p "$work/elsewhere"
cd "$work/elsewhere" || exit 1
"$prefix/bin/sph" check punch 2>&1 | grep -q "$prefix/bin/../share/sph/scenes/punch.yaml" && ok ||
  bad "installed scene by name: $("$prefix/bin/sph" check punch 2>&1 | head -2)"
"$prefix/bin/sph" run punch --out run --quiet --set time.end=0.0004 \
  --set output.every=0.0002 --set output.png=false >/dev/null 2>&1 && [ -f run/summary.json ] && ok ||
  bad "installed run"
echo "install: $pass passed, $fail failed"
[ $fail -eq 0 ]
