#!/usr/bin/env bash
# Formatting and static analysis, both clean on the tree or this fails.
# Usage: scripts/lint.sh [--all]   (--all: clang-tidy on the tests too)
# Needs the compile databases of the release build and, for the fuzz targets,
# of the asan build (or a fuzz-only build) when present.
set -euo pipefail
cd "$(dirname "$0")/.."

mapfile -t sources < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.c')
clang-format --dry-run --Werror "${sources[@]}"
echo "lint: clang-format clean (${#sources[@]} files)"

# clang-tidy on every translation unit of ours, each with the build that compiles it.
# Each translation unit writes its own log: parallel runs sharing one pipe
# interleave their "N warnings generated." lines into fragments no filter can
# tell from a diagnostic.
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
tidy() {
  local build=$1
  shift
  [ "$#" -eq 0 ] && return 0
  # clang's -Wdouble-promotion flags every float passed to a double (the
  # firmware tests' checks); gcc's narrower check stays on in every build
  # (cmake/TonusOptions.cmake turns clang's off the same way).
  # The static analyzer runs in its shallow mode (a smaller budget per function,
  # less inlining): in the default deep mode eight of the daemon's methods took
  # 8-16 s each to exhaust their path budget (log_status: 15 s deep, 0.1 s
  # shallow), and the lint took a third of CI's time; shallow keeps every checker.
  printf '%s\n' "$@" | xargs -P "$(nproc)" -I{} sh -c \
    'clang-tidy -p "$1" --quiet --extra-arg=-Wno-double-promotion \
       --extra-arg=-Xclang --extra-arg=-analyzer-config --extra-arg=-Xclang --extra-arg=mode=shallow \
       "$2" >"$3/$(echo "$2" | tr / _).log" 2>&1' \
    sh "$build" {} "$logs" || true
  # A log may end without a newline ("N warnings generated." does): end each.
  for log in "$logs"/*.log; do cat "$log" && echo; done | grep -vE '^[0-9]+ warnings? (generated|treated)|^Suppressed|^Use -header-filter|^$' || true
  rm -f "$logs"/*.log
}
# The test suite's own translation units are half of them and half the time
# (about 8 s each, mostly parsing doctest, Eigen and spdlog); they build with
# -Werror under gcc and clang alike, so the default pass tidies the code that
# ships (and the fuzz targets, which read untrusted input). --all adds them.
exclude='^tests/|^firmware/targets/(cortex-m4|probe)/'
[ "${1:-}" = "--all" ] && exclude='^tests/fuzz/|^firmware/targets/(cortex-m4|probe)/'
mapfile -t host_tus < <(git ls-files '*.cpp' | grep -vE "$exclude")
mapfile -t fuzz_tus < <(git ls-files 'tests/fuzz/*.cpp')
out=$(tidy build/release "${host_tus[@]}")
for fuzz_build in build/asan build/fuzz; do
  if [ -f $fuzz_build/compile_commands.json ] && grep -q fuzz_stream $fuzz_build/compile_commands.json; then
    out+=$(tidy $fuzz_build "${fuzz_tus[@]}")
    break
  fi
done
if [ -n "$out" ]; then
  echo "$out"
  echo "lint: clang-tidy found problems" >&2
  exit 1
fi
echo "lint: clang-tidy clean"
