#!/usr/bin/env bash
# Mesh bodies through the command (issue 34): a scene beside its mesh
# (relative path), what sph check states about the mesh, a run of the unit
# cube mesh that is the built-in box's bit for bit, the resolved scene
# loaded again from another folder, and each bad mesh refused with exit 2
# at the scene's file:line:col, naming the mesh and the reason, nothing
# written.
set -u
sph=$1
src=$2
. "$(dirname "$0")/harness.sh"
meshes=$src/tests/data/meshes
mkdir -p "$work/case/parts"
cp "$meshes"/*.stl "$work/case/parts/"
cube_scene "$work/case/box.yaml" "{every: 0.002}"
sed 's|{box: {min: \[0, 0, 0\], max: \[1, 1, 1\]}}|{mesh: {file: parts/cube.stl}}|' \
  "$work/case/box.yaml" >"$work/case/mesh.yaml"
grep -q 'parts/cube.stl' "$work/case/mesh.yaml" || bad "the mesh scene was not made"

# sph check from another folder: the mesh is found beside the scene
(cd / && "$sph" check "$work/case/mesh.yaml") >"$work/out" 2>&1
[ $? -eq 0 ] && grep -qF "mesh parts/cube.stl: 12 triangles, 0 open edges, box [0, 0, 0] to [1, 1, 1] m" "$work/out" &&
  grep -qF "volume 1 m^3 (signed); particles 1 m^3, 100.00 % of it" "$work/out" && ok ||
  bad "check: $(cat "$work/out")"
"$sph" check "$work/case/mesh.yaml" --set bodies.0.shape.mesh.file="$meshes/cube_hole.stl" >"$work/out" 2>&1
[ $? -eq 0 ] && grep -qF "11 triangles, 3 open edges" "$work/out" && ok || bad "hole: $(cat "$work/out")"

# the same run as the box, bit for bit
"$sph" run "$work/case/box.yaml" --out "$work/box" --quiet >/dev/null 2>&1 &&
  "$sph" run "$work/case/mesh.yaml" --out "$work/mesh" --quiet >/dev/null 2>&1 || bad "runs failed"
for f in cube_0000.vtp cube_0002.vtp energy.csv; do
  cmp -s "$work/box/$f" "$work/mesh/$f" && ok || bad "$f differs between the box and its mesh"
done
# the run's resolved scene names the mesh wherever it is read from
(cd / && "$sph" check "$work/mesh/scene_used.yaml") >/dev/null 2>"$work/err" && ok ||
  bad "scene_used.yaml: $(cat "$work/err")"

# a boundary near a mesh face selects what the plane of that face does
sed 's|select: {plane: {axis: y, at: 0}}|select: {plane: {axis: z, at: 1}}|' \
  "$work/case/mesh.yaml" >"$work/case/plane.yaml"
sed 's|select: {plane: {axis: y, at: 0}}|select: {near: {file: parts/cube_top.stl}}|' \
  "$work/case/mesh.yaml" >"$work/case/near.yaml"
"$sph" run "$work/case/plane.yaml" --out "$work/plane" --quiet >/dev/null 2>&1 &&
  "$sph" run "$work/case/near.yaml" --out "$work/near" --quiet >/dev/null 2>"$work/err" || bad "near runs: $(cat "$work/err")"
cmp -s "$work/plane/cube_0002.vtp" "$work/near/cube_0002.vtp" && ok || bad "near: not the plane's run"
grep -qF "distance: 0.0833333" "$work/near/scene_used.yaml" && ok || bad "near: no default distance in scene_used.yaml"
sed 's|parts/cube_top.stl|parts/nothing.stl|' "$work/case/near.yaml" >"$work/case/near_bad.yaml"
"$sph" check "$work/case/near_bad.yaml" >/dev/null 2>"$work/err"
[ $? -eq 2 ] && grep -qF "near_bad.yaml:13:" "$work/err" && grep -qF "parts/nothing.stl: no such file" "$work/err" && ok ||
  bad "near, missing file: $(cat "$work/err")"

# refused: exit 2 at the file key (line 9, column 30), nothing written
refuse() { # FILE_OR_KEY=VALUE EXPECTED
  sed "s|parts/cube.stl|$1|" "$work/case/mesh.yaml" >"$work/case/bad.yaml"
  refused_run "$work/case/bad.yaml" "$work/case/bad.yaml:9:" "$2" "$1"
}
refuse parts/none.stl "parts/none.stl: no such file"
: >"$work/case/parts/empty.stl"
refuse parts/empty.stl "parts/empty.stl: the file is empty"
printf 'not a mesh\n' >"$work/case/parts/junk.stl"
refuse parts/junk.stl "parts/junk.stl: not a mesh sph can read"
refuse parts/sheet.stl "mesh parts/sheet.stl encloses no volume (2 triangles, 4 open edges)"
refuse parts/cube_inverted.stl "its volume is negative (-1 m^3): the triangles face inwards; set flip_normals: true"
"$sph" check "$work/case/mesh.yaml" --set bodies.0.shape.mesh.file="$work/case/parts/cube_inverted.stl" \
  --set bodies.0.shape.mesh.flip_normals=true >/dev/null 2>"$work/err" && ok || bad "flip_normals: $(cat "$work/err")"
# units that make the part 1000 times larger: the count, refused
"$sph" check "$work/case/mesh.yaml" --set bodies.0.shape.mesh.file="$work/case/parts/cube_mm.stl" \
  --set 'bodies.0.particles={spacing: 0.05}' --max-memory 1G >/dev/null 2>"$work/err"
[ $? -eq 2 ] && grep -qF "about 8e+12 particles need" "$work/err" && ok || bad "units: $(cat "$work/err")"
"$sph" check "$work/case/mesh.yaml" --set bodies.0.shape.mesh.file="$work/case/parts/cube_mm.stl" \
  --set bodies.0.shape.mesh.units=mm >"$work/out" 2>&1
[ $? -eq 0 ] && grep -qF "210 particles" "$work/out" && ok || bad "units mm: $(cat "$work/out")"

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
