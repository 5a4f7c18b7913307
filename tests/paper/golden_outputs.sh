#!/usr/bin/env bash
# The simulated numbers of every scenario that existed before the controller interface, against
# fingerprints taken with the build before it (tests/paper/golden_outputs.sha256): for each scenario,
# the SHA-256 of trajectory.csv's first 42 columns (t .. tilt_sat: state, rotor speeds and commands,
# setpoints, U, flags; columns added later are not part of it) and of the step and hold figures of
# metrics.json (each step and the hold without its criteria and verdicts: the bands a run is judged
# against are the scenario's, not the simulation's numbers). Usage: golden_outputs.sh BINARY SOURCE_DIR [--write FILE] (--write: take the
# fingerprints with BINARY instead of checking them).
set -euo pipefail
bin="$1"; src="$2"; write="${4:-}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
golden="$src/tests/paper/golden_outputs.sha256"
scenarios=(paper/altitude_step paper/roll_step paper/pitch_step paper/yaw_step examples/position_step
           realism/hover_wind_gusts realism/motor_failure realism/roll_step_noisy_imu)
fingerprints() {
  cd "$src"
  for s in "${scenarios[@]}"; do
    local out="$tmp/$(basename "$s")"
    "$bin" run "scenarios/$s.yaml" --out "$out" --no-plots > "$tmp/log" 2>&1 || { cat "$tmp/log"; exit 1; }
    echo "$(cut -d, -f1-42 "$out/trajectory.csv" | sha256sum | cut -c1-64)  $s/trajectory.csv[1-42]"
    echo "$(/usr/bin/python3 -c 'import json,sys; m=json.load(open(sys.argv[1]));
figures = lambda d: None if d is None else {k: v for k, v in d.items() if k not in ("criteria", "passed")}
print(json.dumps({"steps": [figures(s) for s in m["steps"]], "hold": figures(m.get("hold"))}, sort_keys=True))' \
      "$out/metrics.json" \
      | sha256sum | cut -c1-64)  $s/metrics.json[steps,hold figures]"
  done
}
if [ "$write" != "" ]; then
  fingerprints > "$write"
  exit 0
fi
fingerprints > "$tmp/now"
if ! diff "$golden" "$tmp/now"; then
  echo "FAIL: outputs differ from the fingerprints of the build before the controller interface (above: < then, > now)"
  exit 1
fi
echo "${#scenarios[@]} scenarios: trajectory columns and step figures as before the controller interface"
