#!/usr/bin/env bash
# Soak (prints figures; asserts nothing): a long lockstep run over DDS, plant and controller as two
# processes on this machine, with each process's resident set (VmRSS of /proc/PID/status) sampled
# every INTERVAL_S seconds (default 1). Prints the series' summary per process: first and last sample, min, max, the median
# and maximum of each quarter of the run, and the growth from the first quarter to the last (median
# of the last quarter minus median of the first: warm-up, such as Cyclone's buffers and the first
# discovery, falls in the first quarter; medians, because the plant copies and sorts its round-trip
# series as it finishes, a short spike the last samples may catch) in kB and as slopes in kB per
# hour of wall and of simulated time. The plant records as `quadcosim run --transport dds` makes it
# record (trajectory CSV, run.mcap and its schedule through the controller's parameter services), so
# what a user's long recorded run holds in memory is measured too; RECORD=0 runs without recording.
# The outputs go to a temporary folder (about 0.5 kB per plant tick: 170 MB per simulated hour), and
# are removed at the end; their sizes are printed.
# Usage: bench/soak.sh [BINARY] [SIMULATED_SECONDS] [JSON_OUT] [INTERVAL_S]
#   SIMULATED_SECONDS defaults to 86400 (one simulated day: about 15 min to 1.5 h of wall time at
#   the 20-100x real time lockstep runs here under load, docs/reliability.md). JSON_OUT, when given,
#   receives the summary and the whole series. The scenario is tests/faults/hover_gusts.yaml (position
#   hold in wind, gusts and sensor noise: every tick's command differs).
# Runs on ROS_DOMAIN_ID (default 198) with localhost discovery; run it where no other run uses that
# domain (or in a network namespace of its own: unshare -n, then `ip link set lo up`).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bin="${1:-$root/build/bin/quadcosim}"
seconds="${2:-86400}"
json="${3:-}"
interval="${4:-1}"
scenario="$root/tests/faults/hover_gusts.yaml"
export ROS_DOMAIN_ID="${ROS_DOMAIN_ID:-198}" ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
unset ROS_LOCALHOST_ONLY ROS_STATIC_PEERS CYCLONEDDS_URI
tmp="$(mktemp -d)"
pids=()
cleanup() {
  local rc=$?
  set +e
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null; done
  wait 2>/dev/null
  rm -rf "$tmp"
  exit "$rc"
}
trap cleanup EXIT

record=()
if [ "${RECORD:-1}" = 1 ]; then
  record=(--record "$tmp/trajectory.csv" --mcap "$tmp/run.mcap" --schedule-via /attitude_controller)
  ctl_args=(--no-schedule)
else
  ctl_args=()
fi
"$bin" controller --scenario "$scenario" "${ctl_args[@]}" > "$tmp/controller.log" 2>&1 &
ctl=$!; pids+=("$ctl")
"$bin" plant --scenario "$scenario" --duration "$seconds" --timeout 30 "${record[@]}" > "$tmp/plant.log" 2>&1 &
plant=$!; pids+=("$plant")
echo "soak: $seconds s simulated in lockstep, plant pid $plant, controller pid $ctl, domain $ROS_DOMAIN_ID" >&2

# Samples both processes' VmRSS every INTERVAL_S until the plant exits, then summarises.
/usr/bin/python3 - "$plant" "$ctl" "$tmp/plant.log" "$json" "$interval" "$tmp" <<'PY'
import json, os, re, statistics, sys, time

plant, ctl, plant_log, out, interval = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4], float(sys.argv[5])
folder = sys.argv[6]


def rss_kb(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except (FileNotFoundError, ProcessLookupError):
        return None
    return None  # a zombie has no VmRSS


t0 = time.monotonic()
series = []  # (wall s since start, plant kB, controller kB)
next_t = t0
while True:
    p, c = rss_kb(plant), rss_kb(ctl)
    if p is None:
        break
    series.append((round(time.monotonic() - t0, 3), p, c))
    next_t += interval
    time.sleep(max(0.0, next_t - time.monotonic()))
wall = time.monotonic() - t0

log = open(plant_log).read()
m = re.search(r"([0-9.]+) s simulated in ([0-9.]+) s \(([0-9.]+)x real time\)", log)
summary = {"samples": len(series), "wall_s": round(wall, 1),
           "simulated_s": float(m.group(1)) if m else None, "rtf": float(m.group(3)) if m else None,
           "plant_done": m is not None}
summary["outputs_bytes"] = {f: os.path.getsize(os.path.join(folder, f)) for f in ("trajectory.csv", "run.mcap")
                            if os.path.exists(os.path.join(folder, f))}
for i, name in ((1, "plant"), (2, "controller")):
    values = [s[i] for s in series if s[i] is not None]
    n = len(values)
    if n < 4:
        summary[name] = {"samples": n}
        continue
    q = [values[k * n // 4:(k + 1) * n // 4] for k in range(4)]
    growth = statistics.median(q[3]) - statistics.median(q[0])
    # From the first quarter's middle to the last's: 3/4 of the run, in wall and in simulated hours.
    hours = (series[-1][0] - series[0][0]) * 0.75 / 3600
    sim_hours = summary["simulated_s"] * 0.75 / 3600 if summary["simulated_s"] else 0
    summary[name] = {
        "samples": n, "first_kB": values[0], "last_kB": values[-1], "min_kB": min(values),
        "max_kB": max(values), "quarter_median_kB": [statistics.median(x) for x in q],
        "quarter_max_kB": [max(x) for x in q], "growth_kB": growth,
        "growth_pct": round(100.0 * growth / statistics.median(q[0]), 2),
        "growth_kB_per_hour": round(growth / hours, 1) if hours > 0 else None,
        "growth_kB_per_simulated_hour": round(growth / sim_hours, 1) if sim_hours > 0 else None,
    }
for name in ("plant", "controller"):
    s = summary[name]
    if "growth_kB" not in s:
        print(f"soak: {name}: only {s['samples']} samples", file=sys.stderr)
        continue
    print(f"soak: {name} VmRSS over {s['samples']} samples: first {s['first_kB']} kB, last {s['last_kB']} kB, "
          f"min {s['min_kB']}, max {s['max_kB']}; quarter medians {s['quarter_median_kB']}, quarter maxima "
          f"{s['quarter_max_kB']}; growth first -> last quarter {s['growth_kB']} kB ({s['growth_pct']} %, "
          f"{s['growth_kB_per_hour']} kB per hour of wall time, {s['growth_kB_per_simulated_hour']} kB per simulated hour)")
print(f"soak: {summary['simulated_s']} s simulated in {summary['wall_s']} s wall ({summary['rtf']}x real time); "
      f"outputs {summary['outputs_bytes'] or 'none (RECORD=0)'}")
if out:
    summary["series"] = series
    json.dump(summary, open(out, "w"), indent=1)
sys.exit(0 if summary["plant_done"] else 1)
PY
set +e
wait "$plant"; rc=$?
set -e
[ "$rc" -eq 0 ] || { echo "soak: the plant exited with $rc:" >&2; tail -5 "$tmp/plant.log" >&2; exit 1; }
tail -4 "$tmp/plant.log" >&2
