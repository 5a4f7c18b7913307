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
  # A few clang-format processes, one per core (at most 4), each given an equal share of the files:
  # one process per file took minutes on a loaded machine (it timed out at 120 s). Each difference is
  # reported as "FILE:LINE:COL: error: code should be clang-formatted"; each batch writes its own
  # report, so the lines of two batches never interleave.
  jobs="$(nproc 2> /dev/null || echo 1)"
  ((jobs > 4)) && jobs=4
  ((jobs > ${#files[@]})) && jobs=${#files[@]}
  ((jobs < 1)) && jobs=1
  per=$(((${#files[@]} + jobs - 1) / jobs))
  reports="$(mktemp -d)"
  trap 'rm -rf "$reports"' EXIT
  pids=()
  for ((b = 0; b < jobs; b++)); do
    clang-format --dry-run --Werror "${files[@]:b*per:per}" > /dev/null 2> "$reports/$b" &
    pids+=($!)
  done
  rc=0
  for pid in "${pids[@]}"; do
    wait "$pid" || rc=1
  done
  report="$(cat "$reports"/*)"
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
