#!/usr/bin/env bash
# The README and docs/ pages stay true: every ```yaml block that is a whole
# scene (it has top-level name: and bodies:) passes `sph check`, and every
# `./build/sph check|list|study ... --dry-run` line of a ```sh block runs.
set -u
sph=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0
fail=0
for page in "$src"/README.md "$src"/docs/*.md; do
  # split the page's fenced blocks into numbered files: yaml_N / sh_N
  awk -v dir="$tmp" -v base="$(basename "$page" .md)" '
    /^```yaml/ { n++; out = dir "/" base ".yaml_" n ".yaml"; next }
    /^```sh/   { n++; out = dir "/" base ".sh_" n; next }
    /^```/     { out = ""; next }
    out != ""  { print > out }
  ' "$page"
done
for f in "$tmp"/*.yaml; do
  [ -e "$f" ] || continue
  grep -q '^name:' "$f" && grep -q '^bodies:' "$f" || continue
  if "$sph" check "$f" >/dev/null 2>"$tmp/err"; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1))
    echo "FAIL: $(basename "$f"): $(cat "$tmp/err")"
  fi
done
for f in "$tmp"/*.sh_*; do
  [ -e "$f" ] || continue
  while IFS= read -r line; do
    cmd=${line%%#*}
    case "$cmd" in
    ./build/sph\ check* | ./build/sph\ list* | ./build/sph\ study*--dry-run*) ;;
    *) continue ;;
    esac
    args=${cmd#./build/sph }
    if (cd "$src" && eval "\"$sph\" $args" >/dev/null 2>"$tmp/err"); then
      pass=$((pass + 1))
    else
      fail=$((fail + 1))
      echo "FAIL: $(basename "$f"): $cmd: $(cat "$tmp/err")"
    fi
  done <"$f"
done
echo "$pass passed, $fail failed"
[ $fail -eq 0 ] && [ $pass -gt 0 ]
