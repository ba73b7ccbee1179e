#!/usr/bin/env bash
# Symmetry and skew-symmetry planes (mirror images) over MPI ranks: each
# rank builds the images of its owned and ghost particles in the serial
# order, its ghosts reach two supports around its particles and their
# reflections, and the ghosts' state is exchanged before the images are
# refreshed, so the files are the serial run's bit for bit but the energies
# (check_mpi.py: fields and probes identical, energies to 1e-12). The
# swinging cube (tl-jst, three symmetry and three skew-symmetry planes, its
# analytic initial state set per rank) on 2 ranks as shipped and on 4 at
# spacing 1/16 (at 1/8 four ranks are more than useful), with the serial
# L2 errors in summary.json (added over the ranks in the serial order, no
# rank holding the whole set), and at spacing 1/20 on 3 ranks, tl-jst and
# tl-csph (images of ghosts far from a rank's particles lack neighbours
# there: their moment matrices are not used, and were once singular); the swinging plate (tl-bond, four planes) on 2
# and 4 ranks, and turned by 30 degrees (oblique planes); shortened in time
# only. The same rank count twice writes the same bytes. ul-csph, whose
# particles migrate, places the serial run's images at each rebuild: the
# punch (two symmetry planes, shortened in time only; 35 particles migrate
# on 3 ranks) on 2 and 3 ranks with its frames (and resumed from a
# checkpoint on 2), and the turned plate (oblique planes; to 0.0025 s, before
# its energy growth trips the verdict, its zig-zag not judged: R 0.52 by
# 0.002 s serially) on 2, give the serial files too.
# Usage: run_mpi_symmetry.sh SPH SOURCE_DIR
set -u
sph=$1
src=$2
# shellcheck source=mpi_common.sh
. "$src/tests/mpi/mpi_common.sh"
cube=(run swinging_cube --quiet --set time.end=0.002 --set "$fields")
fine=(run swinging_cube --quiet --set time.end=0.001 --set output.every=0.0005
  --set bodies.0.particles.spacing=0.0625 --set "$fields")
edge=(run swinging_cube --quiet --set time.end=0.0008
  --set bodies.0.particles.spacing=0.05 --set "$fields")
plate=(run swinging_plate_2d --quiet --set time.end=0.005 --set "$fields")
sed -e 's/^reference:.*$//' \
  -e 's/    particles: {spacing: 0.2}/    particles: {spacing: 0.1}\n    transform: {rotate: {angle: 30}}\n    initial_velocity: {uniform: [-0.5, -0.3, 0]}/' \
  -e 's/{plane: {axis: \([xy]\), at: \([02]\)}}/{plane: {axis: \1, at: \2, body: plate}}/' \
  -e 's/at: \[1.9, 1.9\]/at: [0.6, 1.2]/' \
  "$src/scenes/swinging_plate_2d.yaml" >"$work/oblique.yaml"
oblique=(run "$work/oblique.yaml" --quiet --set time.end=0.005 --set "$fields")
punch=(run punch_ul_csph --quiet --set time.end=0.00008
  --set stability.zigzag_max=0
  --set output.every=0.00002 --set "$fields"
  --set 'output.png={width: 320, height: 180, mp4: false}')
# past 4.4e-4 s particles of the punch cross a plane and trade places with
# their images (ul-csph's fold), owned or ghost sources alike
fold=(run punch_ul_csph --quiet --set time.end=0.0006 --set output.every=0.0002
  --set stability.zigzag_max=0 --set stability.fracture_dp=0 --set "$fields")
ul_oblique=(run "$work/oblique.yaml" --quiet --set time.end=0.0025
  --set 'method={name: ul-csph, update_every: 3, eta: 1.4}' --set "$fields"
  --set stability.zigzag_max=0)

compare cube swinging_cube 1e-12 2 -- "${cube[@]}"
compare fine swinging_cube 1e-12 4 -- "${fine[@]}"
compare edge swinging_cube 1e-12 3 -- "${edge[@]}"
compare edge_csph swinging_cube 1e-12 3 -- "${edge[@]}" \
  --set 'method={name: tl-csph}'
compare plate swinging_plate_2d 1e-12 2 4 -- "${plate[@]}"
compare oblique swinging_plate_2d 1e-12 2 4 -- "${oblique[@]}"
compare punch punch_ul_csph 1e-12 2 3 -- "${punch[@]}"
compare fold punch_ul_csph 1e-12 2 -- "${fold[@]}"
compare ul_oblique swinging_plate_2d 1e-12 2 -- "${ul_oblique[@]}"

# the analytic reference's errors, added in the serial order over the ranks
errors() { sed -n '/"error"/,/}/p' "$1/summary.json"; }
same_errors() {
  errors "$work/$1.serial" | grep -q l2_velocity &&
    [ "$(errors "$work/$1.serial")" = "$(errors "$work/$1.np$2")" ]
}
check "cube np 2: the serial L2 errors" same_errors cube 2
check "fine np 4: the serial L2 errors" same_errors fine 4
check "edge np 3: the serial L2 errors" same_errors edge 3
"${mpi[@]}" -np 2 "$sph" "${cube[@]}" --out "$work/cube.np2b" >/dev/null 2>&1
check "cube np 2 twice: identical files" same_bytes "$work/cube.np2" \
  "$work/cube.np2b"
# the punch's particles migrate at its reference updates
migrates() { grep -Eq ' [1-9][0-9]* particles migrated' "$work/punch.log"; }
"${mpi[@]}" -np 3 "$sph" "${punch[@]:0:2}" "${punch[@]:3}" \
  --out "$work/punch.np3b" >"$work/punch.log" 2>&1
check "punch np 3 migrates" migrates
check "punch np 3 twice: identical files" same_bytes "$work/punch.np3" \
  "$work/punch.np3b"
# the images move with their sources into a checkpoint: the newer one
# without a piece, the older one resumes to the uninterrupted run's bytes
ckpt=(run punch_ul_csph --quiet --set time.end=0.00008 --set output.every=0.00001
  --set stability.zigzag_max=0
  --set output.checkpoint_every=0.00002 --set "$fields")
"${mpi[@]}" -np 2 "$sph" "${ckpt[@]}" --out "$work/ck" >/dev/null 2>&1 ||
  fail "punch np 2 with checkpoints"
cp -r "$work/ck" "$work/ckr"
newest=$(grep -l "^step $(sed -n 's/^step //p' "$work/ck"/checkpoint_?.sphm |
  sort -n | tail -1)\$" "$work/ck"/checkpoint_?.sphm)
slot=$(basename "${newest%.sphm}")
rm -f "$work/ckr/${slot}_p1.sphc" "$work/ckr/summary.json" \
  "$work/ckr"/punch_ul_csph_000[78]*
"${mpi[@]}" -np 2 "$sph" "${ckpt[@]}" --resume "$work/ckr" >"$work/log" 2>&1 ||
  fail "punch np 2 resumed: $(cat "$work/log")"
[ -f "$work/ckr/punch_ul_csph_0008.pvtp" ] || fail "punch np 2 resumed: no last frame"
resumed_like "punch np 2 resumed from its older checkpoint" "$work/ck" "$work/ckr"

summary
