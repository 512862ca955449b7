#!/usr/bin/env bash
# Installs everything the build, the tests and the cross builds need on Debian 12. Idempotent:
# packages already present are skipped, so a second run costs a few seconds.
set -euo pipefail

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
APT="$SUDO env DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 -y -q"

host_pkgs=(
  cmake ninja-build g++ pkg-config git mmdebstrap
  libjpeg62-turbo-dev libpng-dev libexif-dev libeigen3-dev libmd-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-14 libclang-rt-14-dev clang-format clang-tidy
  libjpeg-turbo-progs libimage-exiftool-perl time
  g++-aarch64-linux-gnu g++-arm-linux-gnueabihf qemu-user-static
  libcamera-dev libcamera-ipa
  # refocusd's web page: the HTTP library, and the browser, its driver and the load
  # generator the page's browser test and the web load test use.
  libmicrohttpd-dev chromium chromium-driver python3-selenium wrk
  # The throw-away VM that tests the real kernel drivers (tests/vm/run_vm.sh).
  qemu-system-x86 busybox-static kmod cpio linux-headers-amd64
)

missing() {
  local out=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || out+=("$p")
  done
  echo "${out[@]:-}"
}

need=$(missing "${host_pkgs[@]}")
if [ -n "$need" ]; then
  echo "setup: installing: $need"
  # A mirror caught mid-sync fails some index (often a foreign architecture's); what is needed
  # here usually still resolves, and the install below is the real check.
  $APT update >/dev/null 2>&1 || echo "setup: apt-get update reported errors; trying the install anyway"
  $APT install $need >/dev/null
fi
echo "setup: all packages present"
