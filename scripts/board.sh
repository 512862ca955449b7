#!/usr/bin/env bash
# An emulated arm64 board running Debian, from power-on to photo (docs/board-emulation.md):
#
#   scripts/board.sh SUITE DEB     SUITE: bookworm or trixie; DEB: the arm64 package, e.g.
#                                  build/packages/refocusd_0.1.0+deb12_arm64.deb
#
# 1. A Debian arm64 root of SUITE made by mmdebstrap (minbase, systemd, udev, Debian's arm64
#    kernel and its initramfs, curl), cached as a tarball under build/board/SUITE.
# 2. The image: a copy of that root where `apt-get install /tmp/refocusd_*.deb` installs the
#    package with its dependencies from the archive (apt's output is printed: that install on a
#    fresh root is itself a check), plus the board's files from tests/board (its
#    /etc/refocusd.conf with a fresh web token, vivid and uinput loaded at boot, the uinput button
#    service, the scenario service) and tests/vm/uinput_key.cc built for arm64. An ext4 disk
#    image of it is cached, keyed by the root, the .deb's checksum and the board's files.
# 3. qemu-system-aarch64 (-M virt, cortex-a72, 2 cores, 1 GiB, software emulation) boots the
#    root's kernel and initrd with the image as its virtio disk (writes are thrown away). systemd
#    starts refocusd from the package's unit; the scenario (tests/board/scenario.sh) presses the
#    button, checks the photo, its depth, the web page and `refocusd --check-config`, prints
#    `BOARD-RESULT NAME ok|FAILED ...` lines and figures on the serial console, and powers off.
#
# DEB is used as given when it exists. A pattern (build/packages/refocusd_*_arm64.deb, as the
# board tests pass it) stands for the release's own package (+deb12 or +deb13), made now by
# scripts/package.sh SUITE arm64 from the tree as it is.
#
# Exit: 0 every check passed, 1 a check failed or the board did not finish, 2 usage, 77 skipped
# (qemu-system-aarch64, mmdebstrap, qemu-user through binfmt_misc or the cross compiler cannot be
# had). Needs root (mmdebstrap's root mode, chroot, binfmt_misc) and Debian's archive.
# Environment: BOARD_TIMEOUT (seconds for the boot, default 1800), BOARD_KEEP=1 keeps the
# unpacked root of the image (build/board/SUITE/root) for a look.
set -euo pipefail

usage() { sed -n '2,30p' "$0" | sed -n '/^#/p'; exit 2; }
[[ $# -eq 2 ]] || usage
suite=$1 deb_arg=$2
case $suite in bookworm|trixie) ;; *) echo "board: SUITE is bookworm or trixie" >&2; exit 2 ;; esac

log() { echo "board[$suite]: $*"; }
skip() { echo "board[$suite]: SKIP: $*"; exit 77; }
fail() { echo "board[$suite]: FAILED: $*"; exit 1; }
[[ $(id -u) -eq 0 ]] || skip "needs root (mmdebstrap, chroot, binfmt_misc)"
top=$(cd "$(dirname "$0")/.." && pwd)
cache=$top/build/board/$suite
mkdir -p "$cache"
script_start=$(date +%s)
elapsed() { echo $(($(date +%s) - script_start)); }

# One run per suite at a time (both share the cache).
exec 9>"$cache/.lock"
flock -n 9 || { log "another board run for $suite is going on; waiting"; flock 9; }

# --- Tools -------------------------------------------------------------------------------
apt_install() {
  DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 install -y -q "$@" \
    >"$cache/apt-host.log" 2>&1 || { tail -n 5 "$cache/apt-host.log"; return 1; }
}
need=()
command -v qemu-system-aarch64 >/dev/null || need+=(qemu-system-arm)
command -v mmdebstrap >/dev/null || need+=(mmdebstrap)
[[ -e /usr/libexec/qemu-binfmt/aarch64-binfmt-P && -e /usr/lib/binfmt.d/qemu-aarch64.conf ]] ||
  need+=(qemu-user-static)
command -v aarch64-linux-gnu-g++ >/dev/null || need+=(g++-aarch64-linux-gnu)
command -v mkfs.ext4 >/dev/null || need+=(e2fsprogs)
command -v unshare >/dev/null || need+=(util-linux)
if ((${#need[@]})); then
  log "installing ${need[*]}"
  apt_install "${need[@]}" || skip "cannot install ${need[*]}"
fi
command -v qemu-system-aarch64 >/dev/null || skip "no qemu-system-aarch64 (package qemu-system-arm)"
command -v mmdebstrap >/dev/null || skip "no mmdebstrap"
command -v aarch64-linux-gnu-g++ >/dev/null || skip "no aarch64-linux-gnu-g++"

# qemu-user for arm64 programs in the chroots, through binfmt_misc (F: the interpreter is opened
# now, so it works inside the chroot too).
binfmt=/proc/sys/fs/binfmt_misc
if [[ ! -e $binfmt/register ]]; then
  mount -t binfmt_misc binfmt_misc $binfmt 2>/dev/null || skip "cannot mount binfmt_misc"
fi
if [[ ! -e $binfmt/qemu-aarch64 ]]; then
  cat /usr/lib/binfmt.d/qemu-aarch64.conf >$binfmt/register 2>/dev/null ||
    update-binfmts --enable qemu-aarch64 >/dev/null 2>&1 || true
fi
[[ -e $binfmt/qemu-aarch64 ]] && grep -qx enabled $binfmt/qemu-aarch64 ||
  skip "cannot register qemu-aarch64 with binfmt_misc"

# --- The package -------------------------------------------------------------------------
# DEB as given when it exists. Otherwise (a pattern such as build/packages/refocusd_*_arm64.deb,
# as the board tests pass it) the release's own package, made now by scripts/package.sh SUITE
# arm64 from the source tree as it is (an unchanged tree rebuilds nothing), so a stale package
# is never tested.
case $suite in bookworm) release=deb12 ;; trixie) release=deb13 ;; esac
deb=$deb_arg
if [[ ! -f $deb ]]; then
  [[ $deb_arg == *"*"* ]] || fail "no such package: $deb_arg"
  log "making the $suite package: scripts/package.sh $suite arm64 (log $cache/package.log)"
  exec 8>"$top/build/.board-package-$suite.lock"
  flock 8
  bash "$top/scripts/package.sh" "$suite" arm64 >"$cache/package.log" 2>&1 ||
    { tail -n 20 "$cache/package.log"; fail "scripts/package.sh $suite arm64"; }
  flock -u 8
  deb=$(tail -n1 "$cache/package.log")
  [[ -f $deb && $deb == *"+${release}_arm64.deb" ]] || fail "scripts/package.sh made no $release package"
fi
deb=$(cd "$(dirname "$deb")" && pwd)/$(basename "$deb")
[[ $(dpkg-deb -f "$deb" Architecture) == arm64 ]] || fail "$deb is not an arm64 package"
deb_sum=$(sha256sum "$deb" | cut -c1-64)
log "package $(basename "$deb") (sha256 ${deb_sum:0:12})"

# The button program from tests/vm, static so it needs nothing from the root.
uinput_key=$top/build/board/uinput_key-arm64
if [[ ! -x $uinput_key || $top/tests/vm/uinput_key.cc -nt $uinput_key ]]; then
  aarch64-linux-gnu-g++ -static -O2 "$top/tests/vm/uinput_key.cc" -o "$uinput_key.tmp" ||
    fail "cannot build uinput_key for arm64"
  mv "$uinput_key.tmp" "$uinput_key"
fi

# --- The root, cached per suite ------------------------------------------------------------
# Recommends are not installed (mmdebstrap's default): only what the board needs. The initramfs
# holds the modules the board boots from (virtio disk, ext4: MODULES=list, as a board's image
# names its own) rather than Debian's generic MODULES=most: mkinitramfs runs under qemu-user
# here, where the generic one is slow to build (twice in a root) and large, slow to unpack in the
# emulated board too.
packages="systemd,systemd-sysv,udev,kmod,initramfs-tools,linux-image-arm64,curl"
initramfs_modules="virtio_pci virtio_blk ext4"
initramfs_hook='mkdir -p "$1/etc/initramfs-tools/conf.d" "$1/usr/share/initramfs-tools/modules.d" &&
  echo MODULES=list >"$1/etc/initramfs-tools/conf.d/board.conf" &&
  printf "%s\n" '"$initramfs_modules"' >"$1/usr/share/initramfs-tools/modules.d/board"'
recipe="mmdebstrap --arch=arm64 --variant=minbase --include=$packages $suite; $initramfs_hook"
root_key=$(echo "$recipe" | sha256sum | cut -c1-16)
root_tar=$cache/root-$root_key.tar
if [[ ! -f $root_tar ]]; then
  log "making the $suite arm64 root with mmdebstrap (minbase + $packages)"
  t=$(date +%s)
  rm -f "$cache"/root-*.tar
  rm -rf "$cache/root.tmp.tar"
  mmdebstrap --arch=arm64 --variant=minbase --include="$packages" --mode=root --format=tar \
    --essential-hook="$initramfs_hook" \
    "$suite" "$cache/root.tmp.tar" >"$cache/mmdebstrap.log" 2>&1 ||
    { tail -n 30 "$cache/mmdebstrap.log"; fail "mmdebstrap $suite"; }
  mv "$cache/root.tmp.tar" "$root_tar"
  log "root made in $(($(date +%s) - t)) s ($(du -m "$root_tar" | cut -f1) MB)"
else
  log "root: cached $(basename "$root_tar")"
fi

# --- The image, cached per package and board files ------------------------------------------
board_files=(refocusd.conf modules-load.conf modprobe.conf board-button.service
             board-scenario.service scenario.sh)
files_sum=$( (cd "$top" && sha256sum scripts/board.sh tests/vm/uinput_key.cc \
  "${board_files[@]/#/tests/board/}") | sha256sum | cut -c1-16)
image_key=$(echo "$root_key $deb_sum $files_sum" | sha256sum | cut -c1-16)
image=$cache/image-$image_key.img
work=$cache/work  # the image's kernel and initrd
if [[ ! -f $image || ! -f $work/initrd.img ]]; then
  t=$(date +%s)
  rm -f "$cache"/image-*.img
  rm -rf "$work" && mkdir -p "$work"
  root=$cache/root
  rm -rf "$root" && mkdir -p "$root"
  tar -xf "$root_tar" -C "$root" --numeric-owner --xattrs --xattrs-include='*'
  cp "$deb" "$root/tmp/"
  had_resolv=0
  [[ -e $root/etc/resolv.conf || -L $root/etc/resolv.conf ]] && had_resolv=1 &&
    mv "$root/etc/resolv.conf" "$root/etc/resolv.conf.board"
  cp /etc/resolv.conf "$root/etc/resolv.conf"
  # apt installs the package on the fresh root, resolving its dependencies from the archive.
  log "apt-get install $(basename "$deb") on a fresh $suite root"
  set +e
  unshare --mount --propagation private /bin/bash -c '
    set -e
    root=$1 deb=$2
    mount -t proc proc "$root/proc"
    mount --bind /dev "$root/dev"
    mount --bind /dev/pts "$root/dev/pts"
    mount -t tmpfs tmpfs "$root/run"
    export DEBIAN_FRONTEND=noninteractive LC_ALL=C.UTF-8
    chroot "$root" apt-get update -q
    chroot "$root" apt-get install -y "/tmp/$deb"
    chroot "$root" apt-get clean
  ' board "$root" "$(basename "$deb")" >"$cache/apt-install.log" 2>&1
  apt_status=$?
  set -e
  # What apt decided (the packages it added, from which release) and anything it complained
  # about; the whole output stays in apt-install.log.
  awk '/^The following/ { show = 1 } /^(Need to get|Fetched|Selecting|Preparing|Unpacking)/ { show = 0 }
       show || /^(E|W|N):|^dpkg|^Setting up refocusd|[0-9]+ upgraded, / { print "  apt: " $0 }' \
    "$cache/apt-install.log"
  rm -f "$root/etc/resolv.conf" "$root/tmp/$(basename "$deb")"
  ((had_resolv)) && mv "$root/etc/resolv.conf.board" "$root/etc/resolv.conf"
  if ((apt_status != 0)); then
    [[ ${BOARD_KEEP:-0} == 1 ]] || rm -rf "$root"
    fail "apt-get install of the package failed on $suite (above; $cache/apt-install.log)"
  fi
  echo "apt-get install ok" >>"$cache/apt-install.log"
  rm -rf "$root"/var/lib/apt/lists/*

  # The board's files.
  token=$(head -c 24 /dev/urandom | base64 | tr '+/' '-_')
  sed "s|@TOKEN@|$token|" "$top/tests/board/refocusd.conf" >"$root/etc/refocusd.conf"
  install -m 0644 "$top/tests/board/modules-load.conf" "$root/etc/modules-load.d/board.conf"
  install -m 0644 "$top/tests/board/modprobe.conf" "$root/etc/modprobe.d/board.conf"
  install -m 0644 "$top/tests/board/board-button.service" "$root/etc/systemd/system/"
  install -m 0644 "$top/tests/board/board-scenario.service" "$root/etc/systemd/system/"
  install -D -m 0755 "$top/tests/board/scenario.sh" "$root/usr/local/lib/board/scenario.sh"
  install -D -m 0755 "$uinput_key" "$root/usr/local/bin/uinput_key"
  mkdir -p "$root/etc/systemd/system/multi-user.target.wants"
  ln -sf /etc/systemd/system/board-button.service \
    "$root/etc/systemd/system/multi-user.target.wants/board-button.service"
  ln -sf /etc/systemd/system/board-scenario.service \
    "$root/etc/systemd/system/multi-user.target.wants/board-scenario.service"
  # The console is the scenario's: no login prompt on it.
  ln -sf /dev/null "$root/etc/systemd/system/serial-getty@ttyAMA0.service"
  echo board >"$root/etc/hostname"

  kernel=$(ls "$root"/boot/vmlinuz-* | sort -V | tail -n1)
  version=${kernel##*/vmlinuz-}
  [[ -f $root/boot/initrd.img-$version ]] || fail "no initrd for $version in the root"
  cp "$kernel" "$work/vmlinuz"
  cp "$root/boot/initrd.img-$version" "$work/initrd.img"
  echo "$version" >"$work/kernel-version"
  dpkg-query --admindir="$root/var/lib/dpkg" -W -f='${Version}' refocusd >"$work/refocusd-version"

  size=$(($(du -sm "$root" | cut -f1) + 384))
  mkfs.ext4 -q -F -L board -d "$root" "$image.tmp" "${size}M" >/dev/null || fail "mkfs.ext4 -d"
  mv "$image.tmp" "$image"
  [[ ${BOARD_KEEP:-0} == 1 ]] || rm -rf "$root"
  log "image made in $(($(date +%s) - t)) s (${size} MB, kernel $version)"
else
  log "image: cached $(basename "$image")"
fi

# --- Power on ------------------------------------------------------------------------------
console=$cache/console.log
timeout_s=${BOARD_TIMEOUT:-1800}
log "booting $(cat "$work/kernel-version") under qemu-system-aarch64 (software emulation)"
boot_start=$EPOCHREALTIME
set +e
timeout "$timeout_s" qemu-system-aarch64 -M virt -cpu cortex-a72 -smp 2 -m 1024 \
  -nographic -no-reboot -nic none -device virtio-rng-pci \
  -kernel "$work/vmlinuz" -initrd "$work/initrd.img" \
  -append "root=/dev/vda rw console=ttyAMA0 panic=-1 quiet loglevel=3" \
  -drive file="$image",if=virtio,format=raw,snapshot=on </dev/null 2>&1 |
  while IFS= read -r line; do
    # Host time of each console line, in seconds since power-on.
    printf '%s %s\n' "$(awk -v a="$EPOCHREALTIME" -v b="$boot_start" 'BEGIN { printf "%7.1f", a - b }')" \
      "${line//$'\r'/}"
  done >"$console"
qemu_status=${PIPESTATUS[0]}
set -e
boot_s=$(awk -v a="$EPOCHREALTIME" -v b="$boot_start" 'BEGIN { printf "%.0f", a - b }')
grep -o -E 'BOARD-(RESULT|FIGURE|NOTE|DONE) .*' "$console" || true
log "the board ran $boot_s s (qemu status $qemu_status)"

# --- Verdict -------------------------------------------------------------------------------
plan=$(sed -n 's/.*BOARD-PLAN //p' "$console" | tail -n1)
failed=0
[[ -n $plan ]] || { log "the scenario never started"; failed=1; }
for check in $plan; do
  line=$(grep -o -E "BOARD-RESULT $check .*" "$console" | tail -n1 || true)
  if [[ -z $line ]]; then
    log "FAIL $check: no result"; failed=$((failed + 1))
  elif [[ $line != "BOARD-RESULT $check ok"* ]]; then
    failed=$((failed + 1))
  fi
done
grep -q 'BOARD-DONE' "$console" || { log "the scenario did not finish (timeout ${timeout_s} s?)"; failed=$((failed + 1)); }
ready_host=$(grep -m1 'BOARD-RESULT ready ok' "$console" | awk '{ print $1 }' || true)
figure() {
  local v
  v=$(sed -n "s/.*BOARD-FIGURE $1 \([0-9.]*\) .*/\1/p" "$console" | tail -n1)
  echo "${v:-?}"
}
echo "board[$suite]: figures under emulation (qemu-system-aarch64 TCG, cortex-a72 x2, 1 GiB):"
echo "  boot to refocusd ready: $(figure boot_to_ready) s (guest clock from kernel start);" \
  "the scenario saw it ${ready_host:-?} s after power-on (host clock)"
echo "  press to photo: $(figure press_to_photo) s (320x180, 5 frames); refocus rerender: $(figure rerender) s"
echo "  board run power-on to power-off: $boot_s s; whole script: $(elapsed) s"
if ((failed)); then
  echo "board[$suite]: last console lines ($console):"
  grep -v 'BOARD-' "$console" | tail -n 40
  log "$failed check(s) failed"
  exit 1
fi
log "every check passed ($plan)"
