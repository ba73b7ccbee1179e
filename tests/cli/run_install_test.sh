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
# embedding: the installed library, headers and sph.pc build the example,
# which steps an installed scene through the API and writes energy.csv
ex=$work/embed
PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name sph.pc | head -1)")"
export PKG_CONFIG_PATH
if cc "$prefix/share/sph/examples/embed.c" $(pkg-config --cflags --libs sph) -o "$ex" 2>"$work/cc.log"; then
  ok
  mkdir -p "$work/emb" && cd "$work/emb" || exit 1
  "$ex" "$prefix/share/sph/scenes/punch.yaml" time.end=0.0004 output.every=0.0002 >"$work/emb.log" 2>&1 &&
    grep -q "^done: " "$work/emb.log" && grep -q "max |u|" "$work/emb.log" &&
    [ "$(wc -l <energy.csv)" -eq 4 ] && ok || bad "embed run: $(cat "$work/emb.log")"
else
  bad "embed does not build against sph.pc: $(cat "$work/cc.log")"
fi
# the CMake package: find_package(sph) and sph::sph build the same example
mkdir -p "$work/cm"
cat >"$work/cm/CMakeLists.txt" <<CM
cmake_minimum_required(VERSION 3.20)
project(embed C)
find_package(sph REQUIRED)
add_executable(embed $prefix/share/sph/examples/embed.c)
target_link_libraries(embed PRIVATE sph::sph)
CM
if cmake -S "$work/cm" -B "$work/cm/build" -DCMAKE_PREFIX_PATH="$prefix" >"$work/cm.log" 2>&1 &&
  cmake --build "$work/cm/build" >>"$work/cm.log" 2>&1 && [ -x "$work/cm/build/embed" ]; then
  ok
else
  bad "find_package(sph): $(tail -5 "$work/cm.log")"
fi
echo "install: $pass passed, $fail failed"
[ $fail -eq 0 ]
