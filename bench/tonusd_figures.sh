#!/usr/bin/env bash
# tonusd's real-time figures (BENCHMARKS.md): the demo (band simulator, the
# bundled walk, gifts, VMC out) for N seconds at 1 kHz, once alone and once
# with a CPU hog on the other core (tonusd pinned to core 0, `yes` to core 1).
# Prints tick p50 / p99 / max, the overrun share (and the overruns a tick's
# own cost caused), the band report -> VMC latency against its goal (2 ms +
# the output period), and CPU use. Beside each run, the machine's floor in the
# same conditions (tonus-bench-wakeup: an empty loop paced the same way, and a
# spinning one), and tonusd's overrun share against the sleeping floor.
#   bench/tonusd_figures.sh [SECONDS] [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
bin=${2:-build/release}/bin
out=$(mktemp -d)
trap 'rm -rf "$out"; [ -n "${hog:-}" ] && kill "$hog" 2>/dev/null || true' EXIT

run() {  # name, then the command's prefix
  local name=$1
  shift
  "$@" "$bin/tonusd" --demo --seconds "$seconds" --no-control --viewer-port 0 --json "$out/$name.json" >"$out/$name.log" 2>&1 || {
    cat "$out/$name.log" >&2
    exit 1
  }
}

floor() {  # name, then the command's prefix
  local name=$1
  shift
  "$@" "$bin/tonus-bench-wakeup" --seconds "$seconds" >"$out/$name.floor"
  "$@" "$bin/tonus-bench-wakeup" --seconds "$seconds" --busy >"$out/$name.busy"
}

cores=$(nproc)
if [ "$cores" -ge 2 ]; then
  run alone taskset -c 0
  floor alone taskset -c 0
  taskset -c 1 yes >/dev/null &
  hog=$!
  run hog taskset -c 0
  floor hog taskset -c 0
  kill "$hog"
  hog=
else
  run alone env
  floor alone env
fi

python3 - "$out" "$seconds" <<'PY'
import json, os, re, sys
out, seconds = sys.argv[1], sys.argv[2]

def share(path):  # "...: 0.123 %" at the end of tonus-bench-wakeup's line
    m = re.search(r"([0-9.]+) %", open(path).read()) if os.path.exists(path) else None
    return float(m.group(1)) if m else float("nan")

print(f"tonusd --demo --seconds {seconds}: one avatar at 1 kHz, VMC at 60 Hz")
print(f"{'case':<7}{'ticks':>7}{'p50 us':>7}{'p99 us':>7}{'max us':>7}{'overruns':>9}{'share %':>8}{'cost':>5}"
      f"{'floor %':>8}{'spin %':>7}{'/floor':>7}{'rep->vmc p50/p99/max ms':>25}{'goal':>5}{'cpu %':>6}{'rt':>4}")
for name in ("alone", "hog"):
    path = os.path.join(out, name + ".json")
    if not os.path.exists(path):
        continue
    j = json.load(open(path))
    goal = 2.0 + j["output_period_us"] / 1000.0
    lat = f"{j['report_to_vmc_p50_us']/1000:.2f}/{j['report_to_vmc_p99_us']/1000:.2f}/{j['report_to_vmc_max_us']/1000:.2f}"
    floor, spin = share(os.path.join(out, name + ".floor")), share(os.path.join(out, name + ".busy"))
    ratio = 100 * j["overrun_share"] / floor if floor > 0 else float("nan")
    print(f"{name:<7}{j['ticks']:>7}{j['tick_p50_us']:>7.0f}{j['tick_p99_us']:>7.0f}{j['tick_max_us']:>7.0f}"
          f"{j['overruns']:>9}{100*j['overrun_share']:>8.3f}{j['overruns_from_cost']:>5}{floor:>8.3f}{spin:>7.3f}"
          f"{ratio:>7.2f}{lat:>25}{goal:>5.1f}{100*j['cpu_share']:>6.1f}{'yes' if j['realtime_priority'] else 'no':>4}")
print("share: overruns / ticks; cost: overruns whose tick alone took longer than the period;")
print("floor: an empty loop paced the same way, wake-ups over 900 us late; spin: 1 ms slots of a spinning")
print("thread with a gap over 900 us; /floor: tonusd's share over the floor's (runs one after the other).")
PY
