#!/usr/bin/env python3
"""Every doctest TEST_CASE name must survive ctest's discovery.

doctest_discover_tests turns each name into a CMake list element: a ';' in a
name splits it, the registered filter then matches no test, and doctest runs
nothing and exits 0, so the test "passes" without running (47 did, until this
check). Usage: check_test_names.py SOURCE_DIR
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
bad = []
for path in sorted((root / "tests").rglob("*.cpp")):
    for lineno, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        for name in re.findall(r'TEST_CASE\("((?:[^"\\]|\\.)*)"', line):
            if ";" in name:
                bad.append(f"{path.relative_to(root)}:{lineno}: {name}")
if bad:
    print("TEST_CASE names with ';' (ctest would register a filter that runs nothing):")
    print("\n".join(bad))
    sys.exit(1)
print("every TEST_CASE name is safe for ctest")
