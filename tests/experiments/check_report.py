#!/usr/bin/env python3
"""Reads an experiment's JSON report with Python's own json module and checks
the fields outside checks rely on (the issue's interface) and the goals."""
import json
import sys

name, path = sys.argv[1], sys.argv[2]
with open(path, encoding="utf-8") as f:
    r = json.load(f)
assert r["experiment"] == name, r["experiment"]
if name == "cube-on-hand":
    for mode in ("pd_only", "pd_ff"):
        m = r[mode]
        for key in ("hand_error_before_drop_m", "peak_deflection_m", "settling_time_s"):
            assert isinstance(m[key], float) and m[key] >= 0.0, (mode, key, m[key])
        assert isinstance(m["cube_stayed"], bool)
        assert m["gains"]["elbow_kp_nm_per_rad"] > 0.0
    assert r["pd_ff"]["hand_error_before_drop_m"] < 1e-3
    a, b = r["pd_only"]["peak_deflection_m"], r["pd_ff"]["peak_deflection_m"]
    assert abs(a - b) <= 0.1 * max(a, b), (a, b)
    assert r["pd_only"]["cube_stayed"] and r["pd_ff"]["cube_stayed"]
    print(f"cube-on-hand: PD+FF error {1e3 * r['pd_ff']['hand_error_before_drop_m']:.3f} mm, "
          f"peaks {1e3 * a:.1f} / {1e3 * b:.1f} mm")
elif name == "brace":
    for target in ("chest", "head"):
        pts = r[target]
        assert [p["stiffness"] for p in pts] == [0.0, 0.25, 0.5, 0.75, 1.0], pts
        peaks = [p["peak_deflection_m"] for p in pts]
        assert all(x > y for x, y in zip(peaks, peaks[1:])), (target, peaks)
        print(f"brace {target}: {', '.join(f'{1e3 * p:.1f}' for p in peaks)} mm")
assert all(g["met"] for g in r["goals"]), r["goals"]
