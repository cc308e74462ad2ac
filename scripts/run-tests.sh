#!/usr/bin/env bash
# The whole test suite: a release build (gcc) and a sanitizer build (clang,
# ASan+UBSan, which also builds the libFuzzer targets and runs them briefly),
# each with every test; the Cortex-M4F cross build; formatting and clang-tidy.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
step() { echo; echo "=== $* ($((SECONDS - start)) s)"; }

step "release: build and test"
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release

step "asan (clang, ASan+UBSan): build, every test, and time-boxed libFuzzer runs"
cmake --preset asan >/dev/null
cmake --build --preset asan
ctest --preset asan

step "arm (Cortex-M4F cross build)"
cmake --preset arm >/dev/null
cmake --build --preset arm

step "lint: clang-format and clang-tidy"
scripts/lint.sh

step "all passed"
