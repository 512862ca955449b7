#!/usr/bin/env bash
# Installs everything the build, the tests and the cross builds need on Debian 12. Idempotent:
# packages already present are skipped, so a second run costs a few seconds.
set -euo pipefail

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
APT="$SUDO env DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 -y -q"

host_pkgs=(
  cmake ninja-build g++ pkg-config git
  libjpeg62-turbo-dev libpng-dev libexif-dev libeigen3-dev libmd-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-14 libclang-rt-14-dev clang-format clang-tidy
  libjpeg-turbo-progs libimage-exiftool-perl time
  g++-aarch64-linux-gnu g++-arm-linux-gnueabihf qemu-user-static
)
cross_pkgs=()
for arch in arm64 armhf; do
  cross_pkgs+=("libjpeg62-turbo-dev:$arch" "libpng-dev:$arch" "libexif-dev:$arch" "libmd-dev:$arch")
done

missing() {
  local out=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || out+=("$p")
  done
  echo "${out[@]:-}"
}

need=$(missing "${host_pkgs[@]}")
need_cross=$(missing "${cross_pkgs[@]}")
if [ -n "$need_cross" ]; then
  for arch in arm64 armhf; do
    dpkg --print-foreign-architectures | grep -qx "$arch" || $SUDO dpkg --add-architecture "$arch"
  done
fi
if [ -n "$need$need_cross" ]; then
  echo "setup: installing: $need $need_cross"
  $APT update >/dev/null
  # Multi-Arch: same packages must match across architectures, so upgrade those first.
  $APT install $need $need_cross >/dev/null
fi
echo "setup: all packages present"
