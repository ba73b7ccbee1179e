#!/usr/bin/env bash
# A crafted checkpoint with a valid CRC (issue 36 item 8): the verdict's
# frame count at INT_MAX overflowed at the next observation (undefined
# behaviour in src/solver/stability.c); its flags and counts, and the next
# output index, are checked on reading: --resume refuses it (exit 2).
set -u
sph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
args=(--threads 1 --quiet --set 'bodies.0.particles.count=[3,3,3]'
  --set output.png=false --set time.end=0.05 --set output.checkpoint_every=0.01)
"$sph" run spinning_cube --out "$work/a" "${args[@]}" >/dev/null &
pid=$!
for _ in $(seq 500); do
  [ -f "$work/a/checkpoint.sphc" ] && break
  sleep 0.01
done
kill -TERM $pid
wait $pid
[ -f "$work/a/checkpoint.sphc" ] || { echo "FAIL: no checkpoint"; exit 1; }
craft() { # field offset in the verdict, struct format, value, label
  cp -r "$work/a" "$work/b"
  rm -f "$work/b/checkpoint.prev.sphc"
  /usr/bin/python3 - "$work/b/checkpoint.sphc" "$1" "$2" "$3" <<'PY'
import struct, sys, zlib
path, off, fmt, value = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
b = bytearray(open(path, "rb").read())
head = b.index(b"tl-jst") - 8          # the header's particle count
at = head + 152 + off                  # past the header (particles .. next_output)
if off < 0:
    at = head + 152 + off              # a header field, counted back from its end
struct.pack_into("<" + fmt, b, at, value)
b[-4:] = struct.pack("<I", zlib.crc32(bytes(b[:-4])) & 0xffffffff)
open(path, "wb").write(b)
PY
  "$sph" run spinning_cube --resume "$work/b" "${args[@]}" >"$work/log" 2>&1
  local rc=$?
  [ $rc -eq 2 ] && grep -q "$5" "$work/log" || fail "$4: exit $rc: $(cat "$work/log")"
  rm -rf "$work/b"
}
craft 276 i 2147483647 "frames INT_MAX" "verdict of 2147483647 frames"
craft 0 i 7 "stable 7" "verdict flags 7"
craft -4 i 2147483647 "next output INT_MAX" "output index 2147483647 out of range"
echo "$fails failures"
[ $fails -eq 0 ]
