#!/usr/bin/env bash
# Installs the npm packages of a test-side tool folder (pinned by its package-lock.json) once;
# node_modules is not committed. A lock per folder keeps concurrent test runs from installing at
# the same time.
#   usage: npm_ci_once.sh DIR PACKAGE  (PACKAGE: one it installs, whose presence means done;
#          exit non-zero with npm's output when the install fails)
set -euo pipefail
dir="$(cd "$1" && pwd)" marker="$1/node_modules/$2/package.json"
[ -f "$marker" ] && exit 0
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
(
  flock 9
  if [ ! -f "$marker" ]; then
    npm ci --prefix "$dir" --no-audit --no-fund > "$log" 2>&1 ||
      { cat "$log" >&2; echo "npm ci in $dir failed (is the npm registry reachable?)" >&2; exit 1; }
  fi
) 9> "${TMPDIR:-/tmp}/quadcosim-$(basename "$dir")-npm.lock"
