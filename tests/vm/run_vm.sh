#!/bin/bash
# Runs test programs against real kernel drivers in a throw-away VM: a Debian kernel under
# qemu-system-x86_64 (software emulation) booting a busybox initramfs that holds the modules,
# the programs and the libraries they link. Each program runs with LB_REQUIRE_DEVICES=1 and its
# exit status comes back over the serial console as "LBVM-RESULT <name> <status>".
#
#   run_vm.sh --cache DIR --work DIR [--modules "vivid uinput evdev"] [--vimc] [--libcamera]
#             [--tool PROGRAM]... [--timeout SECONDS] TEST...
#
# A TEST is a program, or a scenario script (*.sh, run by busybox sh) that drives the --tool
# programs and the programs under test; all of them lie in /tests, which is on PATH.
#
# --cache holds what is slow to get and shared between build trees (kernel package, vimc.ko);
# --work the initramfs and the console log of this run. --vimc builds the vimc driver out of
# tree from Debian's linux-source package (Debian does not ship it); --libcamera adds the
# libcamera runtime (IPA modules, data) and the udev records libcamera needs to see devices.
#
# Exit: 0 every program passed, 1 a program failed or the VM did not finish, 77 skipped
# (qemu, busybox-static, kmod, cpio, the kernel package or, for --vimc, the kernel headers and
# source cannot be had). Packages: qemu-system-x86 busybox-static kmod cpio; for --vimc
# linux-headers-<version> (installed) and linux-source-6.1 (downloaded here).
set -euo pipefail

cache="" work="" modules="vivid uinput evdev" vimc=0 libcamera=0 timeout_s=300
programs=()
tools=()
while (($#)); do
  case "$1" in
    --cache) cache=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --modules) modules=$2; shift 2 ;;
    --vimc) vimc=1; shift ;;
    --libcamera) libcamera=1; shift ;;
    --tool) tools+=("$2"); shift 2 ;;
    --timeout) timeout_s=$2; shift 2 ;;
    -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
    -*) echo "run_vm.sh: unknown option $1" >&2; exit 2 ;;
    *) programs+=("$1"); shift ;;
  esac
done
[[ -n $cache && -n $work && ${#programs[@]} -gt 0 ]] || { echo "usage: see run_vm.sh --help" >&2; exit 2; }

skip() { echo "SKIP: $*"; exit 77; }
log() { echo "vm: $*"; }

for tool in qemu-system-x86_64 depmod modprobe cpio gzip; do
  command -v "$tool" >/dev/null || skip "$tool not installed (packages qemu-system-x86 kmod cpio)"
done
busybox=$(command -v busybox || true)
[[ -n $busybox ]] || skip "busybox not installed (package busybox-static)"
ldd "$busybox" >/dev/null 2>&1 && skip "$busybox is not static (package busybox-static)"

mkdir -p "$cache/debs" "$work"
cache=$(cd "$cache" && pwd)
work=$(cd "$work" && pwd)

# The kernel: the one linux-image-amd64 points at, unless LB_VM_KERNEL names a version.
version=${LB_VM_KERNEL:-}
if [[ -z $version ]]; then
  version=$({ apt-cache depends linux-image-amd64 2>/dev/null || true; } |
    sed -n 's/.*Depends: linux-image-\([0-9].*-amd64\)$/\1/p' | head -n1)
fi
if [[ -z $version ]]; then
  # No package lists: fall back to a kernel already unpacked in the cache.
  version=$(ls "$cache" | sed -n 's/^kernel-//p' | sort -V | tail -n1)
fi
[[ -n $version ]] || skip "cannot tell the Debian kernel version (run apt-get update)"
kroot=$cache/kernel-$version
if [[ ! -f $kroot/boot/vmlinuz-$version ]]; then
  log "fetching linux-image-$version"
  deb=$(ls "$cache"/debs/linux-image-"$version"_*.deb 2>/dev/null | head -n1 || true)
  if [[ -z $deb ]]; then
    (cd "$cache/debs" && apt-get download "linux-image-$version" >/dev/null 2>&1) ||
      skip "apt-get download linux-image-$version failed"
    deb=$(ls "$cache"/debs/linux-image-"$version"_*.deb | head -n1)
  fi
  rm -rf "$kroot.tmp" && mkdir -p "$kroot.tmp"
  dpkg -x "$deb" "$kroot.tmp"
  rm -rf "$kroot" && mv "$kroot.tmp" "$kroot"
fi
moddir=$kroot/lib/modules/$version

if ((vimc)); then
  headers=/usr/src/linux-headers-$version
  [[ -f $headers/Makefile ]] || skip "vimc needs linux-headers-$version installed"
  command -v make >/dev/null || skip "vimc needs make"
  vimc_ko=$cache/vimc-$version/vimc.ko
  if [[ ! -f $vimc_ko ]]; then
    src_deb=$(ls "$cache"/debs/linux-source-6.1_*.deb 2>/dev/null | head -n1 || true)
    if [[ -z $src_deb ]]; then
      log "fetching linux-source-6.1"
      (cd "$cache/debs" && apt-get download linux-source-6.1 >/dev/null 2>&1) ||
        skip "apt-get download linux-source-6.1 failed"
      src_deb=$(ls "$cache"/debs/linux-source-6.1_*.deb | head -n1)
    fi
    log "building vimc.ko out of tree"
    build=$cache/vimc-$version.build
    rm -rf "$build" && mkdir -p "$build"
    dpkg-deb --fsys-tarfile "$src_deb" | tar -x -C "$build" --wildcards './usr/src/linux-source-*.tar.xz'
    tar -xJf "$build"/usr/src/linux-source-*.tar.xz -C "$build" --wildcards \
      '*/drivers/media/test-drivers/vimc/*'
    src=$(echo "$build"/linux-source-*/drivers/media/test-drivers/vimc)
    make -s -C "$headers" M="$src" CONFIG_VIDEO_VIMC=m modules >"$build/make.log" 2>&1 ||
      { cat "$build/make.log"; echo "vm: vimc build failed"; exit 1; }
    mkdir -p "$cache/vimc-$version"
    cp "$src/vimc.ko" "$vimc_ko.tmp" && mv "$vimc_ko.tmp" "$vimc_ko"
    rm -rf "$build"
  fi
  mkdir -p "$moddir/extra"
  cp "$vimc_ko" "$moddir/extra/vimc.ko"
  modules="$modules vimc"
fi
depmod -b "$kroot" "$version"

# The initramfs.
root=$work/root
rm -rf "$root" && mkdir -p "$root"/{bin,dev,proc,sys,tmp,run,lib/modules,tests}
cp "$busybox" "$root/bin/busybox"

# Modules in dependency order, with the options given after a module's name in modules.conf.
: >"$root/modules.list"
for m in $modules; do
  modprobe -d "$kroot" -S "$version" --show-depends "$m" | while read -r kind path args; do
    [[ $kind == insmod ]] || continue
    name=$(basename "$path")
    grep -q "^/lib/modules/$name" "$root/modules.list" && continue
    cp "$path" "$root/lib/modules/$name"
    opts=""
    [[ $name == vivid.ko ]] && opts="n_devs=1 node_types=0x1"
    echo "/lib/modules/$name $opts" >>"$root/modules.list"
  done
done

copy_with_libs() {  # FILE [DEST]: the file and every shared library ldd lists for it
  local file=$1 dest=${2:-$1}
  mkdir -p "$root$(dirname "$dest")"
  cp -L "$file" "$root$dest"
  { ldd "$file" 2>/dev/null || true; } | { grep -o '/[^ ]*' || true; } | while read -r lib; do
    [[ -e $root$lib ]] && continue
    mkdir -p "$root$(dirname "$lib")"
    cp -L "$lib" "$root$lib"
  done
}

names=()
for p in "${programs[@]}" "${tools[@]}"; do
  name=$(basename "$p")
  if [[ $name == *.sh ]]; then
    cp "$p" "$root/tests/$name"
  else
    copy_with_libs "$p" "/tests/$name"
  fi
done
for p in "${programs[@]}"; do names+=("$(basename "$p")"); done

if ((libcamera)); then
  for d in /usr/lib/x86_64-linux-gnu/libcamera /usr/libexec/libcamera /usr/share/libcamera; do
    [[ -d $d ]] || continue
    mkdir -p "$root$d"
    cp -a "$d/." "$root$d/"
    # IPA modules and proxy workers: each with the libraries it links.
    find "$d" -type f \( -name '*.so' -o -perm -u+x \) | while read -r f; do copy_with_libs "$f"; done
  done
fi

cat >"$root/init" <<INIT
#!/bin/busybox sh
/bin/busybox --install -s /bin
export PATH=/bin:/tests
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
mount -t tmpfs tmp /tmp
mount -t tmpfs run /run
while read -r mod opts; do
  insmod \$mod \$opts || echo "LBVM-MODULE-FAILED \$mod"
done </modules.list
if [ $libcamera = 1 ]; then
  # libudev hides devices udev never initialised; there is no udevd here.
  mkdir -p /run/udev/data
  for dev in /sys/bus/media/devices/* /sys/class/video4linux/*; do
    [ -f \$dev/dev ] && echo I:1 >/run/udev/data/c\$(cat \$dev/dev)
  done
fi
echo LBVM-BOOTED
for t in ${names[*]}; do
  echo "LBVM-START \$t"
  case \$t in
    *.sh) LB_REQUIRE_DEVICES=1 sh /tests/\$t ;;
    *) LB_REQUIRE_DEVICES=1 GTEST_COLOR=no /tests/\$t ;;
  esac
  echo "LBVM-RESULT \$t \$?"
done
echo LBVM-DONE
poweroff -f
INIT
chmod +x "$root/init"
(cd "$root" && find . | cpio -o -H newc --quiet) | gzip -1 >"$work/initramfs.gz"
cp "$kroot/boot/vmlinuz-$version" "$work/vmlinuz"

for attempt in 1 2; do
  log "booting $version with: ${names[*]}"
  start=$(date +%s)
  set +e
  timeout "$timeout_s" qemu-system-x86_64 -accel tcg -m 512M -smp 1 -nographic -no-reboot \
    -kernel "$work/vmlinuz" -initrd "$work/initramfs.gz" \
    -append "console=ttyS0 rdinit=/init panic=-1 quiet loglevel=3" </dev/null >"$work/console.log" 2>&1
  qemu_status=$?
  set -e
  tr -d '\r' <"$work/console.log" >"$work/console.txt"
  cat "$work/console.txt"
  log "VM ran $(($(date +%s) - start)) s (qemu status $qemu_status)"
  # Out of time with no test failed: booted once more. Emulated on one loaded core, the VM has
  # stalled inside libcamera's configure of vimc for the whole timeout, where it takes seconds.
  # A second timeout, or any test's failure, still fails.
  if ((attempt == 1 && qemu_status == 124)) &&
    ! grep -Eq '^LBVM-RESULT [^ ]+ [1-9][0-9]*$' "$work/console.txt"; then
    log "the VM ran out of time with no test failed: booting it once more"
    continue
  fi
  break
done

passed=0 failed=0
for t in "${names[@]}"; do
  status=$(sed -n "s/^LBVM-RESULT $t \([0-9]*\)$/\1/p" "$work/console.txt" | tail -n1)
  if [[ $status == 0 ]]; then
    log "PASS $t"; passed=$((passed + 1))
  else
    log "FAIL $t (status ${status:-none: did not finish})"; failed=$((failed + 1))
  fi
done
grep -q '^LBVM-MODULE-FAILED' "$work/console.txt" && { log "a module failed to load"; failed=$((failed + 1)); }
grep -q '^LBVM-DONE' "$work/console.txt" || { log "the VM did not finish (timeout ${timeout_s} s?)"; failed=$((failed + 1)); }
echo "vm: $passed passed, $failed failed"
((failed == 0))
