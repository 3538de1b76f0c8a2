#!/usr/bin/env bash
# The man pages: `cmake --install BUILD --component man` into a temporary prefix puts one page per
# command into PREFIX/share/man/man1; `man` reads each (by path, and by name through MANPATH),
# with its NAME, OPTIONS (every long option of the command's --help) and EXAMPLES.
# Usage: man_pages.sh BUILD_DIR PREFIX COMMAND_PATH...
set -euo pipefail
build=$1 prefix=$2
shift 2
rm -rf "$prefix"
cmake --install "$build" --prefix "$prefix" --component man >/dev/null
status=0
for exe in "$@"; do
  name=$(basename "$exe")
  page="$prefix/share/man/man1/$name.1"
  if [ ! -f "$page" ]; then
    echo "man_pages: $page was not installed"
    status=1
    continue
  fi
  text=$(MANPATH="$prefix/share/man" MANPAGER=cat MANWIDTH=200 man "$name" 2>&1) || {
    echo "man_pages: man $name failed: $text"; status=1; continue; }
  bypath=$(MANPAGER=cat MANWIDTH=200 man -l "$page" 2>&1)
  [ "$text" = "$bypath" ] || { echo "man_pages: man $name and man -l $page differ"; status=1; }
  for section in NAME SYNOPSIS OPTIONS EXAMPLES; do
    grep -q "^$section" <<<"$text" || { echo "man_pages: $name.1 has no $section"; status=1; }
  done
  grep -q "^ *$name - " <<<"$text" || { echo "man_pages: $name.1's NAME is not '$name - ...'"; status=1; }
  for option in $("$exe" --help | sed -n 's/^  \(-[a-zA-Z], *\)\{0,1\}\(--[a-z0-9-]*\).*/\2/p'); do
    grep -q -- "$option" <<<"$text" || { echo "man_pages: $name.1 lacks $option"; status=1; }
  done
done
[ $status -eq 0 ] && echo "man_pages: $# pages installed and read"
exit $status
