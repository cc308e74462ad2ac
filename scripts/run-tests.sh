#!/usr/bin/env bash
# The whole test suite: release and ASan+UBSan builds with every test, the
# Cortex-M4F cross build, short libFuzzer runs, formatting and clang-tidy.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
step() { echo; echo "=== $* ($((SECONDS - start)) s)"; }

step "release: build and test"
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release

step "asan (ASan+UBSan): build and test"
cmake --preset asan >/dev/null
cmake --build --preset asan
ctest --preset asan

step "arm (Cortex-M4F cross build)"
cmake --preset arm >/dev/null
cmake --build --preset arm

step "fuzz: libFuzzer targets, time-boxed runs"
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz
ctest --preset fuzz

step "lint: clang-format and clang-tidy"
scripts/lint.sh

step "all passed"
