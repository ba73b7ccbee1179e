#!/usr/bin/env bash
# Fails when any C source or header differs from its clang-format rendering.
set -u
fmt=$1
top=$2
cd "$top" || exit 2
files=$(git ls-files '*.c' '*.h' 2>/dev/null || find src include render tests -name '*.[ch]')
[ -n "$files" ] || { echo "no sources found"; exit 2; }
bad=0
for f in $files; do
  if ! "$fmt" --dry-run --Werror --style=file "$f" >/dev/null 2>&1; then
    echo "not clang-format clean: $f"
    bad=1
  fi
done
[ $bad -eq 0 ] && echo "all $(echo "$files" | wc -w) sources are clang-format clean"
exit $bad
