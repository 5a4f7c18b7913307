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
  # One clang-format process for every file (one per file took minutes on a loaded machine): each
  # difference is reported as "FILE:LINE:COL: error: code should be clang-formatted".
  set +e
  report="$(clang-format --dry-run --Werror "${files[@]}" 2>&1 > /dev/null)"
  rc=$?
  set -e
  mapfile -t differ < <(printf '%s\n' "$report" | sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' | sort -u)
  if ((${#differ[@]} > 0)); then
    echo "format: ${#differ[@]} file(s) differ from .clang-format (run scripts/format.sh):" >&2
    printf '  %s\n' "${differ[@]}" >&2
    exit 1
  fi
  if [ "$rc" -ne 0 ]; then
    echo "format: clang-format failed:" >&2
    printf '%s\n' "$report" >&2
    exit 1
  fi
  echo "format: ${#files[@]} files as .clang-format says"
  exit 0
fi
clang-format -i "${files[@]}"
