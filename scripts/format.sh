#!/usr/bin/env bash
# Formats every C++ file of the repository with clang-format and the repository's .clang-format.
# Usage: scripts/format.sh [--check]   (--check: change nothing, list the files that differ, exit 1 if any)
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v clang-format > /dev/null; then
  echo "format: clang-format is not installed (Debian package clang-format)" >&2
  exit 77
fi
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.cc' 2> /dev/null ||
                     find src bench tests -name '*.cpp' -o -name '*.hpp' -o -name '*.h')
if [ "${1:-}" = "--check" ]; then
  differ=()
  for f in "${files[@]}"; do
    if ! clang-format --dry-run --Werror "$f" > /dev/null 2>&1; then differ+=("$f"); fi
  done
  if ((${#differ[@]} > 0)); then
    echo "format: ${#differ[@]} file(s) differ from .clang-format (run scripts/format.sh):" >&2
    printf '  %s\n' "${differ[@]}" >&2
    exit 1
  fi
  echo "format: ${#files[@]} files as .clang-format says"
  exit 0
fi
clang-format -i "${files[@]}"
