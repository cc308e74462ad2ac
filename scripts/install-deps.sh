#!/usr/bin/env bash
# Installs every Debian package tonus needs. Idempotent and quiet; run as root.
# Only the Debian archive is contacted (apt); nothing else is downloaded.
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build git pkg-config
  clang clang-14 clang-format clang-tidy libclang-rt-14-dev lld
  gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi libstdc++-arm-none-eabi-newlib
  # libraries
  doctest-dev libeigen3-dev libbenchmark-dev
  libhidapi-dev libusb-1.0-0-dev libgpiod-dev
  libcli11-dev libtomlplusplus-dev libspdlog-dev libfmt-dev
  liblo-dev liblo-tools libreaderwriterqueue-dev nlohmann-json3-dev libcpp-httplib-dev
  libmujoco-dev
  # tools used by tests and benchmarks
  can-utils valgrind python3
  # emulator for the firmware self-test (STM32F405 = machine netduinoplus2)
  qemu-system-arm
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: need root to install: ${missing[*]}" >&2
  exit 1
fi

export DEBIAN_FRONTEND=noninteractive
echo "install-deps: installing ${#missing[@]} package(s): ${missing[*]}"
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# Quiet on success; the whole apt log on failure.
if ! { apt-get update -qq && apt-get install -y -qq --no-install-recommends "${missing[@]}"; } >"$log" 2>&1; then
  cat "$log" >&2
  echo "install-deps: apt-get failed" >&2
  exit 1
fi
