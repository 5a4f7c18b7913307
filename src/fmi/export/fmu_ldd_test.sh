#!/usr/bin/env bash
# The FMU binary is self-contained: at load time it needs nothing but the C library, the maths
# library and the loader (the C++ runtime is linked in), and it exports the FMI functions only.
# Usage: fmu_ldd_test.sh <quadcosim_fmu.so>
set -euo pipefail
so="$1"
if ! command -v ldd > /dev/null; then
  echo "fmu_ldd_test: ldd is not installed (Debian package libc-bin)" >&2
  exit 77
fi
needed=$(ldd "$so")
echo "$needed"
other=$(echo "$needed" | grep -v -E '^\s*(linux-vdso\.so|libc\.so\.6|libm\.so\.6|/lib(64)?/ld-linux|ld-linux)' || true)
if [ -n "$other" ]; then
  echo "fmu_ldd_test: $so needs more than libc, libm and the loader:" >&2
  echo "$other" >&2
  exit 1
fi
if command -v nm > /dev/null; then
  exported=$(nm -D --defined-only "$so" | awk '{print $3}' | grep -v -E '^fmi[23]' || true)
  if [ -n "$exported" ]; then
    echo "fmu_ldd_test: $so exports symbols besides the fmi2*/fmi3* functions:" >&2
    echo "$exported" | head -20 >&2
    exit 1
  fi
  echo "exports: $(nm -D --defined-only "$so" | grep -c ' T fmi2') fmi2 and $(nm -D --defined-only "$so" | grep -c ' T fmi3') fmi3 functions"
fi
