#!/usr/bin/env bash
# A Debian root of a given release, made with mmdebstrap from Debian's archive and kept in the
# build tree, for building and testing against that release's own packages: the board packages
# (scripts/package.sh) and the libcamera versions of other releases (scripts/libcamera-compat.sh).
#
#   debian-root.sh make DIR SUITE[,SUITE...] ARCH[,ARCH...] PACKAGE...
#       Makes DIR unless it already holds a root made with the same arguments. The first suite
#       is the release; further suites (its -backports) are added to its sources. A package may
#       name a suite (libcamera-dev/trixie-backports) or an architecture (libpng-dev:arm64).
#   debian-root.sh run DIR COMMAND
#       Runs COMMAND with sh in DIR's root, in /src, the source tree mounted there; unmounts
#       again on any exit.
# Needs root (chroot, mount) and the packages mmdebstrap and, for foreign architectures, nothing
# more: the build runs on the machine's own architecture and cross-compiles.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
mirror=${LB_DEBIAN_MIRROR:-http://deb.debian.org/debian}
mounted=""

make_root() {
  local dir=$1 suites=$2 archs=$3
  shift 3
  local stamp_text="$suites $archs $* $mirror"
  mkdir -p "$(dirname "$dir")"
  # One maker per root: a second caller waits, then finds it made.
  exec 9>"$dir.lock"
  flock 9
  if [[ -f $dir/.lb-root && $(cat "$dir/.lb-root") == "$stamp_text" ]]; then
    return 0
  fi
  command -v mmdebstrap >/dev/null || { echo "debian-root: mmdebstrap is not installed" >&2; return 1; }
  local release=${suites%%,*} sources=() s
  IFS=, read -r -a list <<<"$suites"
  for s in "${list[@]}"; do sources+=("deb $mirror $s main"); done
  local include
  include=$(IFS=,; echo "$*")
  rm -rf "$dir.tmp" "$dir"
  echo "debian-root: making $dir ($suites, $archs)" >&2
  if ! mmdebstrap --quiet --mode=root --variant=apt --architectures="$archs" \
      --include="$include" "$release" "$dir.tmp" "${sources[@]}" >"$dir.log" 2>&1; then
    tail -30 "$dir.log" >&2
    rm -rf "$dir.tmp"
    echo "debian-root: mmdebstrap failed (log: $dir.log)" >&2
    return 1
  fi
  echo "$stamp_text" >"$dir.tmp/.lb-root"
  mv "$dir.tmp" "$dir"
}

run_in_root() {
  local dir=$1 command=$2
  [[ -f $dir/.lb-root ]] || { echo "debian-root: $dir is not a root made by this script" >&2; return 1; }
  mkdir -p "$dir/src" "$dir/proc"
  mountpoint -q "$dir/src" && umount "$dir/src"
  mountpoint -q "$dir/proc" && umount "$dir/proc"
  mounted=$dir
  trap 'umount "$mounted/proc" 2>/dev/null; umount "$mounted/src" 2>/dev/null' EXIT
  mount --bind "$top" "$dir/src"
  mount -t proc proc "$dir/proc"
  chroot "$dir" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root LANG=C.UTF-8 \
    sh -c "cd /src && $command"
}

case ${1:-} in
  make) shift; (($# >= 4)) || { echo "usage: debian-root.sh make DIR SUITES ARCHS PACKAGE..." >&2; exit 2; }
        make_root "$@" ;;
  run) shift; (($# == 2)) || { echo "usage: debian-root.sh run DIR COMMAND" >&2; exit 2; }
       run_in_root "$@" ;;
  *) sed -n '2,14p' "$0" >&2; exit 2 ;;
esac
