# Sourced by the one-case-per-CTest-test scripts of the quadcosim binary:
#   source cli_case.sh QUADCOSIM_BINARY SOURCE_DIR CASE
# Sets QC, SRC, CASE and PY (QUADCOSIM_PYTHON, default /usr/bin/python3), makes $TMP (removed on
# exit), and defines `fail MESSAGE`, which prints the case name and the message and exits 1.
set -euo pipefail
QC=$1
SRC=$2
CASE=$3
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL [$CASE]: $*" >&2; exit 1; }
PY=${QUADCOSIM_PYTHON:-/usr/bin/python3}
