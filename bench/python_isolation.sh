#!/usr/bin/env bash
# What flying a Python controller in a process of its own costs per control step (docs/reliability.md,
# "Foreign code"): the hover of tests/faults/hover.yaml with tests/python_node/altitude_pd.py's
# AltitudePD, flown isolated (the default) and with QUADCOSIM_PYTHON_IN_PROCESS=1, each REPEAT times,
# interleaved; prints the wall time of each run and the difference per control step. Not a test: it
# prints figures.
#   usage: bench/python_isolation.sh [BUILD_DIR] [SIMULATED_S] [REPEAT]
set -euo pipefail
build="${1:-build}"; sim_s="${2:-300}"; repeat="${3:-3}"
src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$(cd "$build" && pwd)/bin/quadcosim"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
cp "$src/tests/python_node/altitude_pd.py" "$tmp/"
{ sed "s/duration_s: 30/duration_s: $sim_s/" "$src/tests/faults/hover.yaml" | grep -v '^controller:\|z_des'
  printf 'controller:\n  python: "altitude_pd:AltitudePD"\n'; } > "$tmp/s.yaml"
steps=$((sim_s * 50))
declare -A best
for i in $(seq 1 "$repeat"); do
  for mode in isolated in_process; do
    rm -rf "$tmp/out"
    in_process=0; [ "$mode" = in_process ] && in_process=1
    t0=$(date +%s.%N)
    (cd "$tmp" && QUADCOSIM_PYTHON_IN_PROCESS=$in_process "$bin" run s.yaml --out out --no-plots > /dev/null)
    t1=$(date +%s.%N)
    wall=$(python3 -c "print($t1 - $t0)")
    echo "$mode run $i: $(printf %.3f "$wall") s for $steps control steps ($(python3 -c "print(f'{1e6*$wall/$steps:.2f}')") us/step)"
    prev="${best[$mode]:-1e9}"
    best[$mode]=$(python3 -c "print(min($prev, $wall))")
  done
done
python3 -c "
iso, inp, n = ${best[isolated]}, ${best[in_process]}, $steps
print(f'best of $repeat: isolated {1e6*iso/n:.2f} us/step, in-process {1e6*inp/n:.2f} us/step: '
      f'isolation costs {1e6*(iso-inp)/n:.2f} us per control step ({iso/inp:.2f}x the run)')"
