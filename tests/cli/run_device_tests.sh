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
reason='device: (this sph was built without CUDA|no CUDA device on this machine|method tl-jst has no GPU path)'

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

# (d) sph check --device cuda: where each part runs, then exit 2
"$sph" check "$col" --device cuda >"$work/out" 2>"$work/err"
[ $? -eq 2 ] && grep -q "^device     cuda" "$work/out" &&
  grep -qE "^  method tl-jst +no GPU path: refused" "$work/out" &&
  grep -qE "^  term   essential_bc +no GPU path: refused" "$work/out" && ok ||
  bad "check --device cuda: $(cat "$work/out" "$work/err")"
"$sph" check "$col" --device cpu >"$work/out" 2>"$work/err" &&
  grep -qE "^  method tl-jst +CPU" "$work/out" && ok || bad "check --device cpu"

# (e) --device cpu: the run of the scene without it
"$sph" run "$col" --set "$short" --set "$every" --set output.png=false --out "$work/c1" --quiet >/dev/null 2>&1 &&
  "$sph" run "$col" --device cpu --set "$short" --set "$every" --set output.png=false --out "$work/c2" --quiet >/dev/null 2>&1 &&
  cmp -s "$work/c1/energy.csv" "$work/c2/energy.csv" && ok || bad "--device cpu differs"

echo "device: $pass passed, $fail failed"
[ $fail -eq 0 ]
