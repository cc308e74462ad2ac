#!/usr/bin/env bash
# Per-sample cost of the firmware chain in instructions (callgrind, host build).
# Each workload runs twice (N1 and N2 samples); the difference of the totals
# divided by N2 - N1 cancels start-up, design and generation, so the figure is
# repeatable to the instruction.
#   firmware/bench/callgrind_cost.sh [build/release/bin/tonus-firmware-cost]
set -euo pipefail
bin=${1:-build/release/bin/tonus-firmware-cost}
[ -x "$bin" ] || { echo "callgrind_cost: build it first: cmake --build --preset release --target tonus-firmware-cost" >&2; exit 1; }
command -v valgrind >/dev/null || { echo "callgrind_cost: valgrind not installed" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
total() {  # workload N -> total Ir
  valgrind --tool=callgrind --toggle-collect="*measured_loops*" --callgrind-out-file="$tmp/out" "$bin" "$1" "$2" >/dev/null 2>"$tmp/log"
  grep -E '^(summary|totals):' "$tmp/out" | tail -1 | awk '{print $2}'
}
n1=20000; n2=100000
for w in chain quality frame; do
  a=$(total $w $n1); b=$(total $w $n2)
  per=$(awk -v a="$a" -v b="$b" -v n1=$n1 -v n2=$n2 'BEGIN{printf "%.1f", (b-a)/(n2-n1)}')
  case $w in
    chain) echo "chain_step (1 channel, 2 kHz defaults: DC, HP4, 4 notches, LP4, envelope): $per instructions/sample" ;;
    quality) echo "chain_step + quality_step (1 channel): $per instructions/sample" ;;
    frame) echo "Device, one 8-channel frame (chain + quality + calibration hook + levels/report at 1 kHz): $per instructions/frame" ;;
  esac
done
