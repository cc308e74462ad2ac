#!/usr/bin/env bash
# Installs every Debian package tonus needs, then the live viewer's npm
# packages. Idempotent and quiet; run as root. Only the Debian archive (apt)
# and the npm registry (npm ci of host/viewer/web's package-lock.json) are
# contacted; no browser is downloaded (tests use Debian's chromium).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  # toolchain
  build-essential cmake ninja-build git pkg-config
  clang clang-14 clang-format clang-tidy libclang-rt-14-dev lld
  gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi libstdc++-arm-none-eabi-newlib
  # libraries
  doctest-dev libeigen3-dev libbenchmark-dev
  libhidapi-dev libusb-1.0-0-dev libgpiod-dev
  libcli11-dev libtomlplusplus-dev libspdlog-dev libfmt-dev
  liblo-dev liblo-tools libreaderwriterqueue-dev nlohmann-json3-dev libcpp-httplib-dev zlib1g-dev
  libmujoco-dev
  # the live viewer (host/viewer): WebSocket server over standalone asio; its browser tests
  libwebsocketpp-dev libasio-dev chromium
  # tools used by tests and benchmarks
  can-utils valgrind python3
  # a BVH reader that is not ours (tests/balance/test_blender_import.cpp)
  blender
  # emulator for the firmware self-test (STM32F405 = machine netduinoplus2)
  qemu-system-arm
)

# node and npm for the viewer's page and browser tests: the machine's own when
# present (any Node.js >= 18), else Debian's.
if ! command -v npm >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

log=$(mktemp)
trap 'rm -f "$log"' EXIT

if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "install-deps: need root to install: ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
  # Quiet on success; the whole apt log on failure.
  if ! { apt-get update -qq && apt-get install -y -qq --no-install-recommends "${missing[@]}"; } >"$log" 2>&1; then
    cat "$log" >&2
    echo "install-deps: apt-get failed" >&2
    exit 1
  fi
fi

# The viewer's npm packages (three, @pixiv/three-vrm, puppeteer-core), exactly as locked;
# --ignore-scripts: no install script runs, so no browser is downloaded.
# Skipped while node_modules matches the lock file.
web=host/viewer/web
if [ ! -f "$web/node_modules/.package-lock.json" ] || [ "$web/package-lock.json" -nt "$web/node_modules/.package-lock.json" ]; then
  echo "install-deps: npm ci in $web"
  if ! (cd "$web" && npm ci --ignore-scripts --no-audit --no-fund) >"$log" 2>&1; then
    cat "$log" >&2
    echo "install-deps: npm ci failed in $web" >&2
    exit 1
  fi
fi
