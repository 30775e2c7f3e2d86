#!/usr/bin/env bash
# Checks that every C++ source of the project is formatted by .clang-format (Debian 12's
# clang-format 14; other versions format a few constructs differently). Prints each file that
# differs and the command that formats it; exits 1 if any differ, 2 if clang-format is missing.
# Usage: scripts/check_format.sh [PROJECT_DIR]
set -euo pipefail
root=${1:-"$(dirname "$0")/.."}
cd "$root"
formatter=${CLANG_FORMAT:-clang-format}
if ! command -v "$formatter" >/dev/null 2>&1; then
  echo "check_format: $formatter not found; install Debian's clang-format (scripts/setup.sh does)" >&2
  exit 2
fi
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h')
else
  mapfile -t files < <(find . -path ./build -prune -o -type f \( -name '*.cpp' -o -name '*.hpp' \
    -o -name '*.h' \) -print | grep -v '/build')
fi
unformatted=()
for f in "${files[@]}"; do
  [ -f "$f" ] || continue
  if ! "$formatter" --dry-run -Werror "$f" >/dev/null 2>&1; then unformatted+=("$f"); fi
done
if [ ${#unformatted[@]} -gt 0 ]; then
  echo "check_format: ${#unformatted[@]} of ${#files[@]} files differ from .clang-format:" >&2
  printf '  %s\n' "${unformatted[@]}" >&2
  echo "format them with: $formatter -i ${unformatted[*]}" >&2
  exit 1
fi
echo "check_format: ${#files[@]} files formatted"
