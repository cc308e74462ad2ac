#!/usr/bin/env bash
# tonusd's real-time figures (BENCHMARKS.md): the demo (band simulator, the
# bundled walk, gifts, VMC out) for N seconds at 1 kHz, once alone and once
# with a CPU hog on the other core (tonusd pinned to core 0, `yes` to core 1).
# Prints tick p50 / p99 / max, the overrun share, the band report -> VMC
# latency against its goal (2 ms + the output period), and CPU use.
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
  "$@" "$bin/tonusd" --demo --seconds "$seconds" --no-control --json "$out/$name.json" >"$out/$name.log" 2>&1 || {
    cat "$out/$name.log" >&2
    exit 1
  }
}

cores=$(nproc)
if [ "$cores" -ge 2 ]; then
  run alone taskset -c 0
  taskset -c 1 yes >/dev/null &
  hog=$!
  run hog taskset -c 0
  kill "$hog"
  hog=
else
  run alone env
fi

python3 - "$out" "$seconds" <<'PY'
import json, os, sys
out, seconds = sys.argv[1], sys.argv[2]
print(f"tonusd --demo --seconds {seconds}: one avatar at 1 kHz, VMC at 60 Hz")
print(f"{'case':<10}{'ticks':>8}{'p50 us':>8}{'p99 us':>8}{'max us':>8}{'overruns':>10}{'share %':>9}"
      f"{'wake p99':>9}{'rep->vmc p50/p99/max ms':>26}{'goal ms':>8}{'cpu %':>7}{'rt':>4}")
for name in ("alone", "hog"):
    path = os.path.join(out, name + ".json")
    if not os.path.exists(path):
        continue
    j = json.load(open(path))
    goal = 2.0 + j["output_period_us"] / 1000.0
    lat = f"{j['report_to_vmc_p50_us']/1000:.2f}/{j['report_to_vmc_p99_us']/1000:.2f}/{j['report_to_vmc_max_us']/1000:.2f}"
    print(f"{name:<10}{j['ticks']:>8}{j['tick_p50_us']:>8.0f}{j['tick_p99_us']:>8.0f}{j['tick_max_us']:>8.0f}"
          f"{j['overruns']:>10}{100*j['overrun_share']:>9.3f}{j['wake_late_p99_us']:>9.0f}{lat:>26}{goal:>8.1f}"
          f"{100*j['cpu_share']:>7.1f}{'yes' if j['realtime_priority'] else 'no':>4}")
PY
