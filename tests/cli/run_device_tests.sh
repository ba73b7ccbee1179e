#!/usr/bin/env bash
# Device selection (docs/gpu.md): `--device cuda` and a scene's `device:
# cuda` are refused with exit 2 and nothing written by a build without CUDA,
# on a machine without a GPU, or for a method with no GPU path (whichever
# comes first here), the reason at the device key; a bad value names
# file:line:col; `sph check --device cuda` lists where each part runs;
# `--device cpu` runs as before.
set -u
sph=$1
src=$2
. "$(dirname "$0")/harness.sh"
col="$src/scenes/twisting_column.yaml"
short='time.end=0.0005'
every='output.every=0.00025'
reason='device: (this sph was built without CUDA|no CUDA device on this machine)'
if "$sph" check "$col" --device cuda >/dev/null 2>&1; then
  echo "device: a GPU is here: (a)-(b) need a machine without one (tests/gpu)"
  reason='.'
fi

# (a) --device cuda: exit 2, the reason, no folder
"$sph" run "$col" --device cuda --set "$short" --set "$every" --out "$work/o1" >/dev/null 2>"$work/err"
[ $? -eq 2 ] && grep -qE "$reason" "$work/err" && [ ! -e "$work/o1" ] && ok ||
  bad "run --device cuda: $(cat "$work/err")"

# (b) device: cuda in the scene: the same, at its line and column
sed 's/^dimension: 3$/dimension: 3\ndevice: cuda/' "$col" >"$work/dev.yaml"
"$sph" run "$work/dev.yaml" --set "$short" --set "$every" --out "$work/o2" >/dev/null 2>"$work/err"
rc=$?
line=$(grep -n '^device:' "$work/dev.yaml" | cut -d: -f1)
[ $rc -eq 2 ] && grep -qE "dev.yaml:$line:[0-9]+: $reason" "$work/err" && [ ! -e "$work/o2" ] && ok ||
  bad "device: cuda in the scene: $(cat "$work/err")"

# (c) a bad value: file:line:col and the choices
sed 's/^dimension: 3$/dimension: 3\ndevice: tpu/' "$col" >"$work/bad.yaml"
"$sph" check "$work/bad.yaml" >/dev/null 2>"$work/err"
rc=$?
line=$(grep -n '^device:' "$work/bad.yaml" | cut -d: -f1)
[ $rc -eq 2 ] && grep -q "bad.yaml:$line:" "$work/err" && grep -q cuda "$work/err" && ok ||
  bad "device: tpu: $(cat "$work/err")"
"$sph" run "$col" --device gpu --out "$work/o3" >/dev/null 2>"$work/err"
[ $? -eq 2 ] && grep -q "\-\-device is cpu or cuda" "$work/err" && [ ! -e "$work/o3" ] && ok ||
  bad "--device gpu: $(cat "$work/err")"

# (d) sph check --device cuda: where each part runs (then exit 2 here)
SPH_DEVICE_TWIN=1 "$sph" check "$col" --device cuda >"$work/out" 2>"$work/err"
[ $? -eq 0 ] && grep -q "^device     cuda" "$work/out" &&
  grep -qE "^  method tl-jst +GPU" "$work/out" &&
  grep -qE "^  term   angular_momentum_projection +GPU" "$work/out" &&
  grep -qE "^  term   essential_bc +GPU" "$work/out" && ok ||
  bad "check --device cuda: $(cat "$work/out" "$work/err")"
# a method without a GPU path, a configuration the device step lacks: exit
# 2 at the device key, nothing written
SPH_DEVICE_TWIN=1 "$sph" check colliding_rings --device cuda >"$work/out" 2>"$work/err"
[ $? -eq 2 ] && grep -qE "^  method ul-sph +no GPU path: refused" "$work/out" &&
  grep -q "device: method ul-sph has no GPU path" "$work/err" && ok ||
  bad "check colliding_rings --device cuda: $(cat "$work/out" "$work/err")"
SPH_DEVICE_TWIN=1 "$sph" run "$col" --device cuda --set method.fields=pFJ \
  --set "$short" --set "$every" --out "$work/o4" >/dev/null 2>"$work/err"
[ $? -eq 2 ] && grep -q "device: tl-jst: no device step for tl-jst fields pFJ" "$work/err" &&
  [ ! -e "$work/o4" ] && ok || bad "pFJ --device cuda: $(cat "$work/err")"
"$sph" check "$col" --device cpu >"$work/out" 2>"$work/err" &&
  grep -qE "^  method tl-jst +CPU" "$work/out" && ok || bad "check --device cpu"

# (e) --device cpu: the run of the scene without it
"$sph" run "$col" --set "$short" --set "$every" --set output.png=false --out "$work/c1" --quiet >/dev/null 2>&1 &&
  "$sph" run "$col" --device cpu --set "$short" --set "$every" --set output.png=false --out "$work/c2" --quiet >/dev/null 2>&1 &&
  cmp -s "$work/c1/energy.csv" "$work/c2/energy.csv" && ok || bad "--device cpu differs"

# (f) the run loop on the device step, the host twin standing in for the
# device (SPH_DEVICE_TWIN=1): the CPU run's files to the byte (frames, VTK,
# CSV, probes), all but the run's own records
# (57 steps, frames of 160 x 90)
long=(--set time.end=0.01 --set output.every=0.0025 --set 'output.png={width: 160, height: 90, mp4: false}')
"$sph" run "$col" "${long[@]}" --out "$work/c3" --quiet >/dev/null 2>&1
SPH_DEVICE_TWIN=1 "$sph" run "$col" --device cuda "${long[@]}" --out "$work/g3" \
  --quiet >/dev/null 2>"$work/err" && ok || bad "twin run: $(cat "$work/err")"
diff -rq -x summary.json -x scene_used.yaml -x .sph.manifest -x .sph.lock \
  "$work/c3" "$work/g3" >"$work/diff" && [ -e "$work/g3/energy.csv" ] && ok ||
  bad "twin run differs: $(cat "$work/diff")"

echo "device: $pass passed, $fail failed"
[ $fail -eq 0 ]
