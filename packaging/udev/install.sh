#!/bin/sh
# Installs the band's udev rule and reloads udev, as root:
#   sudo packaging/udev/install.sh
# DESTDIR=/some/root installs under that root and does not touch udev (packaging, tests).
set -eu
here=$(dirname "$0")
target="${DESTDIR:-}/etc/udev/rules.d/70-tonus-band.rules"
install -D -m 0644 "$here/70-tonus-band.rules" "$target"
echo "installed $target"
if [ -z "${DESTDIR:-}" ] && command -v udevadm >/dev/null 2>&1; then
  udevadm control --reload-rules
  udevadm trigger --subsystem-match=hidraw
  echo "udev rules reloaded: replug the band"
fi
