#!/usr/bin/env bash
# The board's Debian package for one release and architecture, built against that release's own
# libraries: a root of the release (scripts/debian-root.sh) with its cross compiler and the
# target's -dev packages installed by apt, a Release build of the programs in it, and cpack with
# dpkg-shlibdeps stating the dependencies the release's apt resolves.
#
#   package.sh [--root-only] SUITE ARCH   SUITE: bookworm (Debian 12) or trixie (Debian 13)
#                                         ARCH:  arm64 or armhf
# Writes build/packages/refocusd_<version>+deb<N>_<ARCH>.deb and prints its path last; the
# release's root stays in build/roots/SUITE-cross-ARCH. --root-only makes the root and stops.
#
#   package.sh native
# On the board itself (Raspberry Pi OS, or any Debian-based system with its own libcamera):
# installs the build's packages with apt, builds against the system's own libraries and writes
# build/packages/refocusd_<version>+local_<arch>.deb for that system alone.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
if [[ ${1:-} == native ]]; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get -o DPkg::Lock::Timeout=600 install -y -q cmake ninja-build g++ pkg-config \
    dpkg-dev file libcamera-dev libjpeg62-turbo-dev libpng-dev libexif-dev libeigen3-dev \
    libmd-dev libmicrohttpd-dev >/dev/null
  tree=$top/build/package/native
  cmake -S "$top" -B "$tree" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLB_TESTS=OFF \
    -DLB_BENCHMARKS=OFF -DLB_DEB_RELEASE=local >/dev/null
  cmake --build "$tree" -j "${JOBS:-$(nproc)}"
  rm -f "$tree"/*.deb
  (cd "$tree" && cpack -G DEB >cpack.log 2>&1) || { cat "$tree/cpack.log"; exit 1; }
  mkdir -p "$top/build/packages"
  cp "$tree"/*.deb "$top/build/packages/"
  echo "$top/build/packages/$(basename "$tree"/*.deb)"
  exit 0
fi
root_only=0
[[ ${1:-} == --root-only ]] && { root_only=1; shift; }
suite=${1:?usage: package.sh [--root-only] bookworm|trixie arm64|armhf, or package.sh native}
arch=${2:?usage: package.sh [--root-only] bookworm|trixie arm64|armhf}
case $suite in
  bookworm) release=deb12 ;;
  trixie) release=deb13 ;;
  *) echo "package: unknown release $suite (bookworm or trixie)" >&2; exit 2 ;;
esac
case $arch in
  arm64) toolchain=aarch64-linux-gnu ;;
  armhf) toolchain=armhf-linux-gnueabihf ;;
  *) echo "package: unknown architecture $arch (arm64 or armhf)" >&2; exit 2 ;;
esac

root=$top/build/roots/$suite-cross-$arch
libs=(libjpeg62-turbo-dev libpng-dev libexif-dev libmd-dev libmicrohttpd-dev libcamera-dev)
bash "$top/scripts/debian-root.sh" make "$root" "$suite" "amd64,$arch" \
  "crossbuild-essential-$arch" cmake ninja-build pkg-config dpkg-dev file libeigen3-dev \
  "${libs[@]/%/:$arch}"
((root_only)) && exit 0

tree=build/package/$suite-$arch
out=$top/build/packages
mkdir -p "$out"
bash "$top/scripts/debian-root.sh" run "$root" "
  set -e
  cmake -S . -B $tree -G Ninja -DCMAKE_TOOLCHAIN_FILE=toolchains/$toolchain.cmake -DLB_MULTIARCH=ON \
    -DCMAKE_BUILD_TYPE=Release -DLB_TESTS=OFF -DLB_BENCHMARKS=OFF -DLB_DEB_RELEASE=$release >/dev/null
  cmake --build $tree -j ${JOBS:-$(nproc)}
  rm -f $tree/*.deb
  cd $tree && DEB_HOST_ARCH=$arch cpack -G DEB >cpack.log 2>&1 || { cat cpack.log; exit 1; }"
debs=("$top/$tree"/*.deb)
((${#debs[@]} == 1)) || { echo "package: expected one .deb in $tree" >&2; exit 1; }
cp "${debs[0]}" "$out/"
echo "$out/$(basename "${debs[0]}")"
