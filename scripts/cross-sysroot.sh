#!/usr/bin/env bash
# Unpacks the target-architecture libraries the firmware links (libjpeg, libpng, zlib, libexif,
# libmd, libmicrohttpd, libcamera, Eigen) into build/sysroot/<arch>, for the unit-test builds
# (the presets aarch64 and armhf); the board's packages are built by scripts/package.sh instead.
# `apt-get download` + `dpkg -x` instead of multiarch installs: multiarch requires the host's and
# the target's versions of every shared package to match exactly, which breaks whenever the
# mirror's security updates differ between architectures.
set -euo pipefail
arch=${1:?usage: cross-sysroot.sh arm64|armhf}
top=$(cd "$(dirname "$0")/.." && pwd)
root="$top/build/sysroot/$arch"
# libmicrohttpd (refocusd's web page) links GnuTLS: the linker resolves a shared library's own
# dependencies, so their runtime packages come too (no -dev: CMake finds libmicrohttpd without
# pkg-config, whose file would ask for gnutls.pc). The stamp lists the packages, so adding one
# here rebuilds an older sysroot.
pkgs=(libjpeg62-turbo libjpeg62-turbo-dev libpng16-16 libpng-dev zlib1g zlib1g-dev
      libexif12 libexif-dev libmd0 libmd-dev
      libmicrohttpd12 libmicrohttpd-dev libgnutls30 libp11-kit0 libffi8 libidn2-0 libunistring2
      libtasn1-6 libnettle8 libhogweed6 libgmp10)

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
if ! dpkg --print-foreign-architectures | grep -qx "$arch"; then
  $SUDO dpkg --add-architecture "$arch"
fi
if ! apt-cache show "libcamera-dev:$arch" >/dev/null 2>&1; then
  $SUDO apt-get -o DPkg::Lock::Timeout=600 update -q >/dev/null 2>&1 || true
fi
# libcamera and every library it needs at run time (the test programs load them under
# qemu-user), less what the cross compiler's own target libraries provide.
mapfile -t camera_pkgs < <(apt-cache depends --recurse --no-recommends --no-suggests \
  --no-conflicts --no-breaks --no-replaces --no-enhances "libcamera-dev:$arch" 2>/dev/null |
  sed -n "s/^\([a-z0-9][a-z0-9.+-]*\):$arch\$/\1/p" |
  grep -vxE 'libc6|libgcc-s1|libstdc\+\+6|gcc-[0-9]+-base' | sort -u)
((${#camera_pkgs[@]} > 2)) || { echo "cross-sysroot: cannot resolve libcamera-dev:$arch" >&2; exit 1; }
for p in "${camera_pkgs[@]}"; do
  [[ " ${pkgs[*]} " == *" $p "* ]] || pkgs+=("$p")
done
stamp="$root/.complete"
[ -f "$stamp" ] && [ "$(cat "$stamp")" = "${pkgs[*]}" ] && exit 0

rm -rf "$root" && mkdir -p "$root/debs"
# Eigen is headers only (Architecture: all); its CMake package must sit in the sysroot too.
(cd "$root/debs" && apt-get download -q libeigen3-dev "${pkgs[@]/%/:$arch}" >/dev/null)
for deb in "$root"/debs/*.deb; do dpkg -x "$deb" "$root"; done
# The -dev symlinks are absolute-free, but pkg-config files name /usr: rewrite to the sysroot.
find "$root/usr/lib" -name '*.pc' -exec sed -i "s|^prefix=/usr|prefix=$root/usr|" {} +
rm -rf "$root/debs"
echo "${pkgs[*]}" > "$stamp"
echo "cross-sysroot: $arch libraries in $root"
