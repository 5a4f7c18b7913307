#!/usr/bin/env bash
# Installs the MCAP reader's npm packages once (tools/npm_ci_once.sh).
#   usage: install.sh  (exit non-zero with npm's output when the install fails)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
exec bash "$here/../npm_ci_once.sh" "$here" @mcap/core
