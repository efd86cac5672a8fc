#!/usr/bin/env bash
# Fails (exit 1) when a C++ source of the project is not as .clang-format wants it, listing the
# files; it changes nothing. To format them: clang-format -i FILE...
# Usage: bash scripts/check_format.sh
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v clang-format >/dev/null; then
  echo "check_format.sh: clang-format not found (bash scripts/setup.sh installs it)" >&2
  exit 1
fi
mapfile -t files < <(git ls-files '*.cc' '*.h' '*.cc.in')
bad=()
for f in "${files[@]}"; do
  if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then bad+=("$f"); fi
done
if [ ${#bad[@]} -gt 0 ]; then
  echo "check_format.sh: ${#bad[@]} of ${#files[@]} files differ from .clang-format:" >&2
  printf '  %s\n' "${bad[@]}" >&2
  echo "check_format.sh: see the changes with clang-format FILE | diff FILE -" >&2
  exit 1
fi
echo "check_format.sh: ${#files[@]} files formatted as .clang-format wants"
