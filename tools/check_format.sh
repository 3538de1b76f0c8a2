#!/usr/bin/env bash
# Fails, naming each file, when a tracked C++ file differs from what clang-format makes of it with
# the repository's .clang-format (Google base, 100 columns). `clang-format -i FILE` fixes one.
set -euo pipefail
cd "$(dirname "$0")/.."
bad=0
while IFS= read -r f; do
  if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then
    echo "calf: $f is not clang-formatted (clang-format -i $f)" >&2
    bad=1
  fi
done < <(git ls-files '*.cc' '*.h' 2>/dev/null ||
  find format encoder decoder player samples tests -name '*.cc' -o -name '*.h')
exit "$bad"
