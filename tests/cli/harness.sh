# Shared by the cli test scripts (sourced): a temporary folder $work removed
# on exit, and the pass/fail counters with ok and bad MESSAGE.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pass=0
fail=0
ok() { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL: $*"; }

# cube_scene FILE OUTPUT: the spinning rubber cube on a clamped base
# (5 x 6 x 7 particles, 0.004 s) with `output: OUTPUT`.
cube_scene() {
  cat >"$1" <<YAML
name: cube
dimension: 3
method: {name: tl-jst}
materials:
  rubber: {model: neo-hookean, density: 1100, youngs_modulus: 17e6, poisson_ratio: 0.45}
bodies:
  - name: cube
    material: rubber
    shape: {box: {min: [0, 0, 0], max: [1, 1, 1]}}
    particles: {count: [5, 6, 7]}
    initial_velocity: {rotation: {axis: y, omega: 10, center: [0.5, 0, 0.5]}}
boundaries:
  - {name: base, select: {plane: {axis: y, at: 0}}, clamp: true}
time: {end: 0.004}
output: $2
YAML
}

# refused_run SCENE PLACE TEXT LABEL: "$sph run SCENE" exits 2 with PLACE
# and TEXT in its error and writes nothing
refused_run() {
  rm -rf "$work/bad"
  "$sph" run "$1" --out "$work/bad" --quiet >/dev/null 2>"$work/err"
  local rc=$?
  [ $rc -eq 2 ] && grep -qF "$2" "$work/err" && grep -qF -- "$3" "$work/err" &&
    [ ! -e "$work/bad" ] && ok || bad "$4 (exit $rc): $(cat "$work/err")"
}
