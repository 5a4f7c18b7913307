#!/usr/bin/env bash
# Installs the client's npm packages (pinned by package-lock.json) once; node_modules is not
# committed. A lock keeps concurrent test runs from installing at the same time.
#   usage: install.sh  (exit non-zero with npm's output when the install fails)
set -euo pipefail
dir="$(cd "$(dirname "$0")" && pwd)"
[ -f "$dir/node_modules/@foxglove/ws-protocol/package.json" ] && exit 0
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
(
  flock 9
  if [ ! -f "$dir/node_modules/@foxglove/ws-protocol/package.json" ]; then
    npm ci --prefix "$dir" --no-audit --no-fund > "$log" 2>&1 ||
      { cat "$log" >&2; echo "npm ci in $dir failed (is the npm registry reachable?)" >&2; exit 1; }
  fi
) 9> "${TMPDIR:-/tmp}/quadcosim-foxglove-verify-npm.lock"
