#!/usr/bin/env bash
# The mp4 after a run: a tiny run with an odd frame size gives a non-empty
# <scene>.mp4 (no .part left) whose frame count (ffprobe) equals the number
# of PNG frames, at output.png.fps, padded to even dimensions, H.264 when
# ffmpeg has libx264; output.png.mp4: false writes none; without ffmpeg on
# PATH the run prints one notice and succeeds; a failing ffmpeg is a
# warning, not a failed run; summary.json times the sinks and the mp4.
# Skipped (exit 77) when ffmpeg or ffprobe is not installed.
set -u
sph=$1
src=$2
command -v ffmpeg >/dev/null && command -v ffprobe >/dev/null || {
  echo "ffmpeg/ffprobe not installed: skipped"
  exit 77
}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
scene=$src/scenes/twisting_column.yaml
tiny=(--quiet --threads 1 --set "bodies.0.particles.count=[3, 7, 3]" --set time.end=0.02
  --set output.every=0.005 --set output.vtk=false --set output.png.width=161
  --set output.png.height=97)
probe() { # file, entry
  ffprobe -v error -count_frames -select_streams v:0 -show_entries "stream=$2" \
    -of default=noprint_wrappers=1:nokey=1 "$1"
}

# a tiny run: 5 frames in, 5 frames out
"$sph" run "$scene" --out "$work/a" "${tiny[@]}" --set output.png.fps=10 >"$work/out" 2>"$work/err"
rc=$?
mp4=$work/a/twisting_column.mp4
pngs=$(ls "$work/a/frames"/twisting_column_*.png 2>/dev/null | wc -l)
if [ $rc -ne 0 ] || [ ! -s "$mp4" ]; then
  fail "tiny run (exit $rc) wrote no mp4: $(cat "$work/out" "$work/err")"
else
  frames=$(probe "$mp4" nb_read_frames)
  [ "$pngs" -eq 5 ] && [ "$frames" = "$pngs" ] || fail "mp4 has $frames frames, $pngs PNGs"
  [ "$(probe "$mp4" width)x$(probe "$mp4" height)" = 162x98 ] || fail "mp4 not padded to 162x98"
  [ "$(probe "$mp4" pix_fmt)" = yuv420p ] || fail "mp4 is not yuv420p"
  [ "$(probe "$mp4" r_frame_rate)" = 10/1 ] || fail "mp4 rate $(probe "$mp4" r_frame_rate), expected 10/1"
  if ffmpeg -hide_banner -encoders 2>/dev/null | grep -q " libx264 "; then
    [ "$(probe "$mp4" codec_name)" = h264 ] || fail "libx264 available but the mp4 is $(probe "$mp4" codec_name)"
  fi
  grep -qF "mp4: $mp4 (5 frames" "$work/out" || fail "no mp4 line: $(cat "$work/out")"
  [ -s "$work/err" ] && fail "stderr not empty: $(cat "$work/err")"
  ls "$work/a"/*.part >/dev/null 2>&1 && fail "a .part file is left"
  grep -q '"sinks": {.*"png": [0-9].*"mp4": [0-9]' "$work/a/summary.json" ||
    fail "summary.json lacks sinks.png/mp4: $(grep sinks "$work/a/summary.json")"
fi

# --overwrite with fewer frames: the old frames and mp4 do not linger
"$sph" run "$scene" --out "$work/a" "${tiny[@]}" --set time.end=0.01 --overwrite >/dev/null 2>&1 ||
  fail "--overwrite run"
[ "$(ls "$work/a/frames" | wc -l)" -eq 3 ] && [ "$(probe "$mp4" nb_read_frames)" = 3 ] ||
  fail "after --overwrite: $(ls "$work/a/frames" | wc -l) PNGs, mp4 of $(probe "$mp4" nb_read_frames) frames"

# switched off
"$sph" run "$scene" --out "$work/b" "${tiny[@]}" --set output.png.mp4=false >"$work/out" 2>&1
[ $? -eq 0 ] && [ ! -e "$work/b/twisting_column.mp4" ] && ! grep -q mp4 "$work/out" ||
  fail "mp4: false: $(cat "$work/out"); $(ls "$work/b")"

# no ffmpeg on PATH: one notice, a successful run
PATH=$work/nowhere "$sph" run "$scene" --out "$work/c" "${tiny[@]}" >"$work/out" 2>"$work/err"
rc=$?
[ $rc -eq 0 ] && [ "$(grep -c "mp4 skipped: ffmpeg not found" "$work/out")" -eq 1 ] &&
  [ ! -e "$work/c/twisting_column.mp4" ] || fail "without ffmpeg (exit $rc): $(cat "$work/out" "$work/err")"

# a failing ffmpeg: a warning with its message, the run still succeeds
mkdir "$work/bin"
printf '#!/bin/sh\necho "frobnication error" >&2\nexit 3\n' >"$work/bin/ffmpeg"
chmod +x "$work/bin/ffmpeg"
PATH=$work/bin:$PATH "$sph" run "$scene" --out "$work/d" "${tiny[@]}" >"$work/out" 2>"$work/err"
rc=$?
[ $rc -eq 0 ] && grep -q "warning: .*ffmpeg failed (exit 3): frobnication error" "$work/err" &&
  [ ! -e "$work/d/twisting_column.mp4" ] && ! ls "$work/d"/*.part >/dev/null 2>&1 ||
  fail "failing ffmpeg (exit $rc): $(cat "$work/out" "$work/err")"

echo "$fails failed"
[ $fails -eq 0 ]
