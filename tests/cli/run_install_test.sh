#!/usr/bin/env bash
# cmake --install into a temporary prefix: the binary, the man page, the
# completion, the scenes and studies land in place, and the installed sph
# runs an installed scene by name from another folder (no source tree).
# The library for embedding: libsph.so with its SONAME links, only the
# public headers, sph.pc and the CMake package; a C program outside the tree
# built with pkg-config and with find_package(sph) runs an installed scene
# through the API, and a Python script outside the tree imports the
# installed sph package (which finds the installed libsph.so) and runs one.
set -u
build=$1
python=${2:-/usr/bin/python3}
. "$(dirname "$0")/harness.sh"
prefix=$work/prefix
unset SPH_LIBRARY PYTHONPATH
cmake --install "$build" --prefix "$prefix" >"$work/log" 2>&1 || bad "install: $(cat "$work/log")"
for f in bin/sph share/man/man1/sph.1 share/bash-completion/completions/sph \
  share/sph/scenes/twisting_column.yaml share/sph/studies/swinging_cube.sh \
  include/sph/sph.h include/sph/status.h; do
  [ -e "$prefix/$f" ] && ok || bad "not installed: $f"
done
# the library under its SONAME, the public headers only, no static library
lib=$(find "$prefix" -name 'libsph.so.*.*.*' | head -1)
libdir=$(dirname "${lib:-$prefix/lib/none}")
soname=$(readelf -d "$lib" 2>/dev/null | grep -oE 'SONAME.*\[[^]]*\]' | grep -oE 'libsph[^]]*')
[ -n "$lib" ] && [ -n "$soname" ] && [ -L "$libdir/$soname" ] && [ -L "$libdir/libsph.so" ] &&
  [ "$(readlink -f "$libdir/libsph.so")" = "$(readlink -f "$lib")" ] && ok ||
  bad "libsph.so and its links: $(ls -l "$libdir" 2>&1)"
headers=$(cd "$prefix/include" && find . -type f | sort | tr '\n' ' ')
[ "$headers" = "./sph/sph.h ./sph/status.h " ] && ok || bad "installed headers: $headers"
statics=$(find "$prefix" -name '*.a')
[ -z "$statics" ] && ok || bad "static libraries installed: $statics"
mkdir -p "$work/elsewhere"
cd "$work/elsewhere" || exit 1
"$prefix/bin/sph" check punch 2>&1 | grep -q "$prefix/bin/../share/sph/scenes/punch.yaml" && ok ||
  bad "installed scene by name: $("$prefix/bin/sph" check punch 2>&1 | head -2)"
"$prefix/bin/sph" run punch --out run --quiet --set time.end=0.0004 \
  --set output.every=0.0002 --set output.png=false >/dev/null 2>&1 && [ -f run/summary.json ] && ok ||
  bad "installed run"

# the installed example, a C program over the public API only: loads a
# scene with overrides, runs it in the current folder, prints the verdict
src=$prefix/share/sph/examples/embed.c
scene=$prefix/share/sph/scenes/punch.yaml
sets=(time.end=0.0004 output.every=0.0002 output.png.width=160 output.png.height=90)
run_embed() { # run_embed NAME PROGRAM: runs it in $work/NAME; its outputs are there
  mkdir -p "$work/$1" && (cd "$work/$1" && "$2" "$scene" "${sets[@]}") >"$work/$1.log" 2>&1 &&
    grep -q "^done: .*verdict stable" "$work/$1.log" && [ -f "$work/$1/summary.json" ] &&
    [ "$(wc -l <"$work/$1/energy.csv")" -eq 4 ] && [ -n "$(find "$work/$1" -name '*.png')" ] &&
    ok || bad "$1 run: $(cat "$work/$1.log")"
}

# pkg-config: -I<prefix>/include -L<libdir> -lsph, nothing private
PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name sph.pc | head -1)")"
export PKG_CONFIG_PATH
flags=$(pkg-config --cflags --libs sph 2>&1)
case " $flags " in
  *" -lsph "*) ok ;;
  *) bad "pkg-config --libs sph: $flags" ;;
esac
[ "$(pkg-config --variable=includedir sph | xargs realpath)" = "$(realpath "$prefix/include")" ] && ok ||
  bad "pkg-config includedir: $(pkg-config --variable=includedir sph)"
echo "$flags" | grep -q "sph_" && bad "private libraries in sph.pc: $flags" || ok
# (-lm: the example's own sqrt and fmax)
if cc -std=c11 -Wall -Werror "$src" $flags -lm -o "$work/embed_pc" 2>"$work/cc.log"; then
  ok
  readelf -d "$work/embed_pc" | grep -q "NEEDED.*\[$soname\]" && ok || bad "not linked to $soname"
  LD_LIBRARY_PATH=$libdir run_embed pc "$work/embed_pc"
else
  bad "a program does not build against sph.pc: $(cat "$work/cc.log")"
fi
# the CMake package: find_package(sph) and sph::sph (no library path needed
# to run: CMake's build rpath)
mkdir -p "$work/cm"
cat >"$work/cm/CMakeLists.txt" <<CM
cmake_minimum_required(VERSION 3.20)
project(embed C)
find_package(sph 0 REQUIRED)
add_executable(embed $src)
target_link_libraries(embed PRIVATE sph::sph m)
CM
if cmake -S "$work/cm" -B "$work/cm/build" -DCMAKE_PREFIX_PATH="$prefix" >"$work/cm.log" 2>&1 &&
  cmake --build "$work/cm/build" >>"$work/cm.log" 2>&1 && [ -x "$work/cm/build/embed" ]; then
  ok
  run_embed cm_run "$work/cm/build/embed"
else
  bad "find_package(sph): $(tail -5 "$work/cm.log")"
fi

# Python: the installed package (found by PYTHONPATH here, as for any
# prefix Debian's python3 does not search) finds the installed libsph.so
init=$(find "$prefix" -path '*/sph/__init__.py' | head -1)
if [ -n "$init" ]; then
  ok
  pydir=$(dirname "$(dirname "$init")")
  mkdir -p "$work/py" && cd "$work/py" || exit 1
  cat >"$work/py/study.py" <<PY
import sys
import sph
assert sph.__file__.startswith("$pydir"), sph.__file__
assert sph._capi.library()._name.startswith("$prefix/"), sph._capi.library()._name
with sph.load("punch", set=sys.argv[1:], out="pyrun") as run:
    run.advance()
    f = run.fields()
    print("particles", len(f["position"]), "kinetic", run.energy().kinetic)
print("verdict:", run.summary.verdict, run.summary.state)
PY
  PYTHONPATH=$pydir "$python" study.py "${sets[@]}" >"$work/python.log" 2>&1 &&
    grep -q "verdict: stable completed" "$work/python.log" && [ -f pyrun/summary.json ] && ok ||
    bad "python run: $(cat "$work/python.log")"
else
  bad "the Python package is not installed"
fi
echo "install: $pass passed, $fail failed"
[ $fail -eq 0 ]
