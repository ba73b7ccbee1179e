#!/usr/bin/env bash
# The bash completion and the man page follow the binary: completion offers
# the commands, a command's options from its usage and the shipped scenes;
# the man page, generated from the usage texts, names every command and
# renders without a groff warning.
set -u
sph=$1
src=$2
. "$(dirname "$0")/harness.sh"
. "$src/tools/sph-completion.bash"

complete_line() { # words... : COMPREPLY of the last word
  COMP_WORDS=("$@")
  COMP_CWORD=$((${#COMP_WORDS[@]} - 1))
  COMPREPLY=()
  _sph
  printf '%s\n' "${COMPREPLY[@]}"
}
cd "$src" || exit 1
[ "$(complete_line "$sph" re)" = render ] && ok || bad "command: $(complete_line "$sph" re)"
complete_line "$sph" run --o | grep -qx -- --out && ok || bad "run --o: $(complete_line "$sph" run --o)"
complete_line "$sph" run --o | grep -qx -- --overwrite && ok || bad "run --overwrite"
complete_line "$sph" render --r | grep -qx -- --range && ok || bad "render --range"
complete_line "$sph" run twist | grep -qx twisting_column && ok || bad "scene names: $(complete_line "$sph" run twist)"
complete_line "$sph" check colliding_r | grep -qx colliding_rings && ok || bad "check scene"
# --set keys of the scene given, defaults included
complete_line "$sph" run punch --set method.c | grep -qx "method.cfl=" && ok ||
  bad "--set keys: $(complete_line "$sph" run punch --set method.c)"
complete_line "$sph" study colliding_rings --vary bodies.1.particles.sp | grep -qx "bodies.1.particles.spacing=" &&
  ok || bad "--vary keys: $(complete_line "$sph" study colliding_rings --vary bodies.1.particles.sp)"

man=$work/sph.1
bash "$src/tools/gen_manpage.sh" "$sph" >"$man" || bad "gen_manpage.sh failed"
for c in run check study list imgdiff bench render; do
  grep -q "^\.SS $c\$" "$man" || bad "man page lacks $c"
done
grep -q -- '--set' "$man" && ok || bad "man page lacks the options"
if command -v groff >/dev/null; then
  warn=$(groff -man -Tutf8 -ww "$man" 2>&1 >/dev/null)
  [ -z "$warn" ] && ok || bad "groff: $warn"
fi

echo "completion and man page: $pass passed, $fail failed"
[ $fail -eq 0 ]
