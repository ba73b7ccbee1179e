#!/usr/bin/env bash
# Colliding rings (scenes/colliding_rings.yaml, A8, seed 002 sec. 6.3): the
# shipped scene at 0.06, 0.07 and 0.08 c0 to 0.03 s, past the rebound, with
# the full Riemann dissipation (default) and eq. 16's limiter; plots the
# booked total and the kinetic energy per ring against seed 002's 65.88 ->
# 55.61 J/m (0.06 c0, t = 0.012) into outputs/rings_energy/energy.png.
# Options: --out DIR (default outputs/rings_energy), --dry-run (validate
# the six runs with sph check, run nothing); others pass through to sph run
# (e.g. --threads 1). PLOT_ONLY=1 redraws the plot from the runs in DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
sph=${SPH:-./build/sph}
out=outputs/rings_energy
dry=0
pass=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --dry-run) dry=1; shift ;;
    *) pass+=("$1"); shift ;;
  esac
done
for v in 0.06:7.0710678 0.07:8.2496 0.08:9.428; do
  [ "${PLOT_ONLY:-0}" = 1 ] && break
  frac=${v%%:*}
  speed=${v##*:}
  for d in full limited; do
    sets=(--set method.dissipation=$d --set output.png=false
      --set output.vtk=false
      --set "bodies.0.initial_velocity.uniform=[$speed,0,0]"
      --set "bodies.1.initial_velocity.uniform=[-$speed,0,0]")
    if [ $dry = 1 ]; then
      "$sph" check scenes/colliding_rings.yaml "${sets[@]}" >/dev/null
      continue
    fi
    mkdir -p "$out"
    "$sph" run scenes/colliding_rings.yaml --overwrite --quiet \
      --out "$out/${frac}_$d" "${sets[@]}" ${pass[@]+"${pass[@]}"} || true
  done
done
if [ $dry = 1 ]; then
  echo "6 runs valid, nothing run"
  exit 0
fi
command -v gnuplot >/dev/null || { echo "plots skipped: gnuplot not found"; exit 0; }
gnuplot <<GP
set terminal pngcairo size 1000,600 font ",11"
set yrange [0:135]
set output "$out/energy.png"
set datafile separator ","
set key top right
set xlabel "t [s]"
set ylabel "energy per ring [J/m]"
set title "Colliding rings (ul-sph ENOG, dp 0.001): total (solid) and kinetic (dashed)"
plot for [f in "0.06 0.07 0.08"] "$out/".f."_full/energy.csv" every ::1 \
       using 1:(\$4/2) with lines lw 2 title f." c0 total", \
     for [f in "0.06 0.07 0.08"] "$out/".f."_full/energy.csv" every ::1 \
       using 1:(\$2/2) with lines dt 2 title f." c0 kinetic", \
     "$out/0.08_limited/energy.csv" every ::1 using 1:(\$2/2) with lines \
       lc rgb "red" title "0.08 c0 kinetic, eq. 16 limiter", \
     "-" using 1:2 with points pt 7 ps 1.5 lc rgb "black" title "seed 002, 0.06 c0"
0,65.88
0.012,55.61
e
GP
echo "wrote $out/energy.png"
