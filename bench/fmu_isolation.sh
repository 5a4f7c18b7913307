#!/usr/bin/env bash
# What running an FMU in a process of its own costs per plant tick (docs/reliability.md, "Foreign
# code"): the hover of tests/faults/hover.yaml with the test plant FMU of tests/foreign (no fault),
# flown isolated (the default) and with `in_process: true`, each REPEAT times; prints the wall time of
# each run and the difference per tick. Not a test: it prints figures.
#   usage: bench/fmu_isolation.sh [BUILD_DIR] [SIMULATED_S] [REPEAT]
set -euo pipefail
build="${1:-build}"; sim_s="${2:-300}"; repeat="${3:-3}"
src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="$build/bin/quadcosim"; fmu="$build/tests/foreign/faulty_plant.fmu"
[ -f "$fmu" ] || { echo "no $fmu: build the target faulty_fmus first"; exit 2; }
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
cp "$fmu" "$tmp/"
for mode in isolated in_process; do
  extra=""; [ "$mode" = in_process ] && extra=", in_process: true"
  { sed "s/duration_s: 30/duration_s: $sim_s/" "$src/tests/faults/hover.yaml"; echo "plant: {fmu: faulty_plant.fmu$extra}"; } \
    > "$tmp/$mode.yaml"
done
ticks=$((sim_s * 100))
declare -A best
for mode in isolated in_process isolated in_process; do :; done
for i in $(seq 1 "$repeat"); do
  for mode in isolated in_process; do
    rm -rf "$tmp/out"
    t0=$(date +%s.%N)
    "$bin" run "$tmp/$mode.yaml" --out "$tmp/out" --no-plots > /dev/null
    t1=$(date +%s.%N)
    wall=$(python3 -c "print($t1 - $t0)")
    echo "$mode run $i: $(printf %.3f "$wall") s for $ticks ticks ($(python3 -c "print(f'{1e6*$wall/$ticks:.2f}')") us/tick)"
    prev="${best[$mode]:-1e9}"
    best[$mode]=$(python3 -c "print(min($prev, $wall))")
  done
done
python3 -c "
iso, inp, n = ${best[isolated]}, ${best[in_process]}, $ticks
print(f'best of $repeat: isolated {1e6*iso/n:.2f} us/tick, in-process {1e6*inp/n:.2f} us/tick: '
      f'isolation costs {1e6*(iso-inp)/n:.2f} us per plant tick ({iso/inp:.2f}x the run)')"
