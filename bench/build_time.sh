#!/usr/bin/env bash
# Where a cold build's CPU time goes (docs/performance.md, "Build time"): configures a fresh build
# directory without ccache, builds the given targets with every compile and link run under
# /usr/bin/time, and prints the CPU seconds (user + system) by target and the heaviest units with their
# peak memory. CPU time, not wall time: it barely depends on what else the machine runs.
#   bench/build_time.sh BUILD_DIR [TARGET...] [-- CMAKE_ARGS...]   (default target: all; -j from
#   QUADCOSIM_JOBS, default 2; BUILD_DIR is deleted first)
#   BUILD_TIME_TOP=N lists the N heaviest units (default 20).
#   The compiler is the build's own choice (clang when installed, CMakeLists.txt); to measure GCC:
#   bench/build_time.sh BUILD quadcosim -- -DCMAKE_CXX_COMPILER=g++ -DCMAKE_C_COMPILER=gcc
# Launcher mode (internal): bench/build_time.sh --log LOG COMMAND... runs COMMAND, appending
# "user sys max_rss_kB wall CC|LD output" to LOG.
set -euo pipefail
if [ "${1:-}" = "--log" ]; then
  log="$2"
  shift 2
  out=""
  kind=LD
  args=("$@")
  for ((i = 0; i < ${#args[@]}; i++)); do
    case "${args[i]}" in
      -c) kind=CC ;;
      -o) out="${args[i + 1]}" ;;
    esac
  done
  exec /usr/bin/time -a -o "$log" -f "%U %S %M %e $kind $PWD/$out" "$@"
fi

if [ $# -lt 1 ]; then
  echo "usage: bench/build_time.sh BUILD_DIR [TARGET...] [-- CMAKE_ARGS...]" >&2
  exit 2
fi
if [ ! -x /usr/bin/time ]; then
  echo "build_time: /usr/bin/time is not installed (Debian package time)" >&2
  exit 77
fi
self="$(cd "$(dirname "$0")" && pwd)/$(basename "$0")"
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
build="$1"
shift
targets=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  targets+=(--target "$1")
  shift
done
[ "${1:-}" = "--" ] && shift
rm -rf "$build"
mkdir -p "$build"
build="$(cd "$build" && pwd)"
log="$build/build_time.log"
launcher="$self;--log;$log"
cmake -S "$source_dir" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER_LAUNCHER="$launcher" \
  -DCMAKE_C_COMPILER_LAUNCHER="$launcher" -DCMAKE_CXX_LINKER_LAUNCHER="$launcher" \
  -DCMAKE_C_LINKER_LAUNCHER="$launcher" "$@" > "$build/build_time.configure.txt"
start=$(date +%s)
cmake --build "$build" -j"${QUADCOSIM_JOBS:-2}" "${targets[@]}" > "$build/build_time.build.txt" 2>&1
echo "build_time: $(($(date +%s) - start)) s wall; the build's output in $build/build_time.build.txt"
echo "build_time: $(sed -n 's/^-- The CXX compiler identification is //p' "$build/build_time.configure.txt")"
python3 - "$log" "${BUILD_TIME_TOP:-20}" << 'EOF'
import collections, re, sys
rows, by_target, units = [], collections.Counter(), collections.Counter()
for line in open(sys.argv[1]):
    p = line.split(None, 5)
    if len(p) < 6:
        continue
    cpu = float(p[0]) + float(p[1])
    m = re.search(r"CMakeFiles/([^/]+)\.dir/(.*)$", p[5].strip())
    target = "(link)" if p[4] == "LD" or not m else m.group(1)
    unit = m.group(2) if m else p[5].strip().rsplit("/", 1)[-1]
    by_target[target] += cpu
    units[target] += 1
    rows.append((cpu, int(p[2]) // 1024, f"{target}: {unit}"))
total = sum(r[0] for r in rows)
print(f"total: {total:.1f} CPU s ({total / 60:.2f} CPU min), {len(rows)} compiler/linker runs")
print("by target (CPU s, runs):")
for target, cpu in by_target.most_common():
    print(f"  {cpu:7.1f} {units[target]:4d}  {target}")
print("heaviest units (CPU s, peak MB):")
for cpu, rss, name in sorted(rows, reverse=True)[: int(sys.argv[2])]:
    print(f"  {cpu:6.1f} {rss:5d}  {name}")
EOF
