#!/usr/bin/env bash
# Builds the libcamera backend with -Werror against the libcamera of other Debian releases and
# runs its unit tests there, each in a root of that release (scripts/debian-root.sh): the host
# build covers Debian 12's own 0.0.3.
#
#   libcamera-compat.sh [--root-only] [RELEASE...]
#       bookworm-backports  libcamera 0.3.2
#       trixie              libcamera 0.4.0 (Debian 13)
#       trixie-backports    libcamera 0.7.1
#   With no RELEASE, all three. Ends with "libcamera-compat: N passed, M failed". --root-only
#   makes the releases' roots (build/roots/RELEASE) and stops.
set -uo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
root_only=0
[[ ${1:-} == --root-only ]] && { root_only=1; shift; }
releases=("$@")
((${#releases[@]})) || releases=(bookworm-backports trixie trixie-backports)
deps=(g++ cmake ninja-build pkg-config libjpeg62-turbo-dev libpng-dev libexif-dev libeigen3-dev
      libmd-dev libmicrohttpd-dev libgtest-dev libgmock-dev)
passed=0 failed=0
for release in "${releases[@]}"; do
  case $release in
    bookworm-backports) suites=bookworm,bookworm-backports camera=libcamera-dev/bookworm-backports ;;
    trixie) suites=trixie camera=libcamera-dev ;;
    trixie-backports) suites=trixie,trixie-backports camera=libcamera-dev/trixie-backports ;;
    *) echo "libcamera-compat: unknown release $release" >&2; exit 2 ;;
  esac
  root=$top/build/roots/$release
  tree=build/compat/$release
  if ((root_only)); then
    bash "$top/scripts/debian-root.sh" make "$root" "$suites" amd64 "${deps[@]}" "$camera" ||
      exit 1
    continue
  fi
  if bash "$top/scripts/debian-root.sh" make "$root" "$suites" amd64 "${deps[@]}" "$camera" &&
     bash "$top/scripts/debian-root.sh" run "$root" "
       set -e
       echo \"libcamera-compat: $release: libcamera \$(pkg-config --modversion libcamera)\"
       cmake -S . -B $tree -G Ninja -DCMAKE_BUILD_TYPE=Debug -DLB_BENCHMARKS=OFF >/dev/null
       cmake --build $tree -j ${JOBS:-$(nproc)} --target libcamera_test refocusd
       $tree/tests/hal/libcamera/libcamera_test --gtest_brief=1"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "libcamera-compat: $release: FAILED"
  fi
done
((root_only)) && exit 0
echo "libcamera-compat: $passed passed, $failed failed"
((failed == 0))
