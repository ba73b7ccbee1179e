#!/usr/bin/env bash
# libsph.so exports exactly the public API: the functions marked SPH_API in
# include/sph/sph.h and include/sph/status.h, every function those headers
# declare is marked, and nm -D --defined-only lists those names and nothing
# else (no private sph_ function, no libgomp lock, no dependency's symbol).
set -u
lib=$1
src=$2
fail=0
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }
headers=("$src/include/sph/sph.h" "$src/include/sph/status.h")
# a declaration at column 0 naming an sph_ function must carry SPH_API
unmarked=$(grep -hE '^[A-Za-z_][A-Za-z_0-9 *]*\bsph_[a-z_0-9]+\(' "${headers[@]}" |
  grep -vE '^(SPH_API|typedef|#)')
[ -z "$unmarked" ] || bad "public declarations without SPH_API: $unmarked"
want=$(cat "${headers[@]}" | tr '\n' ' ' | grep -oE 'SPH_API[^;(]*\(' |
  grep -oE 'sph_[a-z_0-9]+ *\($' | tr -d ' (' | sort -u)
[ -n "$want" ] || bad "no SPH_API function found in the headers"
have=$(nm -D --defined-only "$lib" | awk '{print $NF}' | sed 's/@.*//' | sort -u)
extra=$(comm -13 <(echo "$want") <(echo "$have"))
missing=$(comm -23 <(echo "$want") <(echo "$have"))
[ -z "$extra" ] || bad "exported but not public: $(echo $extra)"
[ -z "$missing" ] || bad "public but not exported: $(echo $missing)"
soname=$(readelf -d "$lib" | grep -oE 'SONAME.*\[[^]]*\]' | grep -oE '\[.*\]' | tr -d '[]')
case "$soname" in
  libsph.so.[0-9]*) ;;
  *) bad "SONAME is '$soname', not libsph.so.MAJOR" ;;
esac
echo "exports: $(echo "$have" | wc -l) symbols, $(echo "$want" | wc -l) public, $fail failed"
[ $fail -eq 0 ]
