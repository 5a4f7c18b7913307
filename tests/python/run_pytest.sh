#!/usr/bin/env bash
# Runs the pytest suite of the Python module: run_pytest.sh PYTHON BUILD_PYTHON_DIR QUADCOSIM SOURCE_DIR
# Exits 77 (skipped) when the module was not built or PYTHON has no pytest.
set -euo pipefail
python="$1" module_dir="$2" quadcosim="$3" source_dir="$4"
if ! compgen -G "$module_dir/quadcosim/_quadcosim*.so" >/dev/null; then
  echo "SKIP: the Python module was not built (no $module_dir/quadcosim/_quadcosim*.so; needs pybind11-dev)"
  exit 77
fi
if ! "$python" -c "import pytest" 2>/dev/null; then
  echo "SKIP: $python has no pytest (Debian: python3-pytest)"
  exit 77
fi
export PYTHONPATH="$module_dir${PYTHONPATH:+:$PYTHONPATH}" QUADCOSIM_BIN="$quadcosim" QUADCOSIM_SOURCE_DIR="$source_dir"
cd "$source_dir"
exec "$python" -m pytest -p no:cacheprovider -q "$source_dir/tests/python"
