#!/usr/bin/env python3
"""Reads `tonus ik --json` with Python's own json module: the fields outside
checks rely on (the issue's interface), their types, and the goals on a walk."""
import json
import sys

path, trackers = sys.argv[1], int(sys.argv[2])
with open(path, encoding="utf-8") as f:
    r = json.load(f)
assert r["trackers"] == trackers, r["trackers"]
assert isinstance(r["frames"], int) and r["frames"] > 100, r["frames"]
for key in ("mpjpe_cm", "mpjpe_upper_cm", "mpjpe_lower_cm", "hand_error_max_mm", "head_error_max_mm",
            "jitter_ratio"):
    assert isinstance(r[key], float) and r[key] >= 0.0, (key, r[key])
mapping = r["mapping"]
for bone in ("Hips", "Head", "LeftHand", "RightHand", "LeftFoot", "RightFoot"):
    assert isinstance(mapping[bone], str) and mapping[bone], (bone, mapping.get(bone))
assert [run["condition"] for run in r["runs"]] == ["clean", "noise", "dropouts", "noise_filtered"]
clean = r["runs"][0]
assert clean["mpjpe_cm"] == r["mpjpe_cm"]
# Goals on a walk: 3 points at most 9 cm (half of Final IK's 18.1), 6 points at most 3 cm; the head on
# its tracker (3 points place the pelvis for it), most wrist samples within 1 mm.
assert r["mpjpe_cm"] <= (9.0 if trackers == 3 else 3.0), r["mpjpe_cm"]
assert r["mpjpe_upper_cm"] < r["mpjpe_cm"] or trackers == 6
assert clean["hand_within_1mm_share"] >= 0.8, clean["hand_within_1mm_share"]
if trackers == 3:
    assert r["head_error_max_mm"] <= 1.0, r["head_error_max_mm"]
for run in r["runs"][1:]:
    assert run["mpjpe_cm"] >= 0.9 * clean["mpjpe_cm"], (run["condition"], run["mpjpe_cm"])
noisy, filtered = r["runs"][1], r["runs"][3]
assert filtered["jitter_ratio"] < 0.5 * noisy["jitter_ratio"], (filtered["jitter_ratio"], noisy["jitter_ratio"])
print(f"tonus ik ({trackers} trackers): MPJPE {r['mpjpe_cm']:.2f} cm (upper {r['mpjpe_upper_cm']:.2f}, lower "
      f"{r['mpjpe_lower_cm']:.2f}), wrists within 1 mm {100 * clean['hand_within_1mm_share']:.1f} %, "
      f"jitter x{r['jitter_ratio']:.2f}")
