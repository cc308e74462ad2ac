#!/usr/bin/env bash
# The main job on embedded defaults (no hardware, no config file): builds the
# release preset and runs what tonus does end to end today.
set -euo pipefail
cd "$(dirname "$0")/.."

cmake --preset release >/dev/null
cmake --build --preset release

# tonusd, the host daemon, on embedded defaults: the band simulator spawned
# with a co-contraction that rises and falls, the bundled CMU walk as the
# tracker, a ball and cubes thrown on a schedule, VMC sent to 127.0.0.1:39539
# (any avatar engine or OSC receiver there sees it); then its summary.
build/release/bin/tonusd --demo --seconds 20 --json build/release/tonusd_demo.json

# A simulated band stream pushed through the USB-HID and CAN bindings over
# lossy links and decoded back, with every message accounted for.
build/release/bin/tonus demo --seconds 5 --loss 0.01 --duplication 0.002 --reorder 0.002 --seed 1

# The physics core: the humanoid standing on the ground, a 1 kg cube dropped
# on its hand, a ball thrown at its chest; what happened and what it cost.
build/release/bin/tonus physics --seconds 3

# The ZMP balance filter on a bundled CMU walk (tests/data/SOURCES.md): the
# ZMP checked against the feet's support polygon, the waist leaned, turned and
# shifted where it leaves it, the corrected clip, a JSON report and an SVG plot
# written, and the written clip judged under every estimator of the family.
# Exit code 1 is that verdict (on this clip the 4 Hz estimators still find 5 %
# of the frames outside, docs/balance.md), not a failure of the run; 2 is.
zmp_status=0
build/release/bin/tonus zmp tests/data/cmu_02_walk.bvh -o build/release/cmu_02_walk_balanced.bvh \
  --json build/release/cmu_02_walk_balance.json --svg build/release/cmu_02_walk_balance.svg || zmp_status=$?
if [ "$zmp_status" -gt 1 ]; then exit "$zmp_status"; fi

# The avatar controller (dual PD: stiff simulation A feeds forward into weak
# simulation B): the paper's cube experiment, PD only against PD + feedforward,
# with a JSON report and an SVG plot.
build/release/bin/tonus experiment cube-on-hand --json build/release/cube_on_hand.json \
  --svg build/release/cube_on_hand.svg

# Full-body pose from a headset and two controllers: the bundled CMU walk's
# own trackers (synthesized at fixed offsets), calibrated from a T-pose and
# solved by IK, against the clip's full body; clean, noisy and with dropouts.
build/release/bin/tonus ik tests/data/cmu_02_walk.bvh --trackers 3 --json build/release/cmu_02_walk_ik.json \
  --svg build/release/cmu_02_walk_ik.svg
