#!/bin/bash
# Checks a board package made by scripts/package.sh as an installer and the board would see it:
# the files at their places, the conffile, the architecture and release in the version, a
# dependency for every library the programs link (each library's package looked up in ROOT, the
# release's own root that the package was built in), and the packaged refocusd running under
# qemu-user with ROOT's libraries: --version lists the libcamera backend, and --check-config
# checks the camera, the button and the photo folder besides the file. The packaged
# configuration must read (no line of it is refused), and with its camera, button and folder
# pointed at ones this machine has (the synthetic camera, a FIFO, a new folder) it must pass;
# where the machine lacks /dev/video0 and /var/lib/refocusd (the usual build host) it must name
# both.
#
#   check_deb.sh DEB ROOT
#
# Exit 0 when every check passes, 1 otherwise, 77 (skip) without dpkg-deb or qemu-user.
set -euo pipefail
deb=$(realpath "${1:?usage: check_deb.sh DEB ROOT}")
root=$(realpath "${2:?usage: check_deb.sh DEB ROOT}")
source_dir=$(cd "$(dirname "$0")/../../.." && pwd)

fail() { echo "check_deb: $*" >&2; exit 1; }

command -v dpkg-deb >/dev/null || { echo "SKIP: dpkg-deb not installed"; exit 77; }
field() { dpkg-deb -f "$deb" "$1"; }
arch=$(field Architecture)
case $arch in
  arm64) qemu=qemu-aarch64-static machine=AArch64 triple=aarch64-linux-gnu ;;
  armhf) qemu=qemu-arm-static machine=ARM triple=arm-linux-gnueabihf ;;
  *) fail "architecture $arch, not arm64 or armhf" ;;
esac
command -v "$qemu" >/dev/null || { echo "SKIP: $qemu not installed"; exit 77; }
emulator=("$qemu" -L "$root")
version=$(sed -n 's/^project(lensblur VERSION \([0-9.]*\).*/\1/p' "$source_dir/CMakeLists.txt")
[[ -n $version ]] || fail "cannot read the project's version"
[[ -d $root/var/lib/dpkg ]] || fail "$root is not a Debian root"
release=$(sed -n 's/^VERSION_ID="\([0-9]*\)"/\1/p' "$root/etc/os-release")
[[ -n $release ]] || fail "cannot tell the release of $root"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "check_deb: $(basename "$deb") against Debian $release"
dpkg-deb -c "$deb" >"$work/contents.txt"
cat "$work/contents.txt"
for entry in "-rwxr-xr-x ./usr/bin/refocusd" "-rwxr-xr-x ./usr/bin/refocus" \
             "-rw-r--r-- ./lib/systemd/system/refocusd.service" "-rw-r--r-- ./etc/refocusd.conf" \
             "-rw-r--r-- ./usr/share/refocusd/www/index.html"; do
  mode=${entry%% *} path=${entry#* }
  grep -qE "^$mode root/root +[0-9]+ [0-9-]+ [0-9:]+ $path\$" "$work/contents.txt" ||
    fail "the package lacks $path with mode $mode owned by root"
done

[[ $(field Package) == refocusd ]] || fail "package name $(field Package), not refocusd"
[[ $(field Version) == "$version+deb$release" ]] ||
  fail "version $(field Version), not $version+deb$release"
dpkg-deb --ctrl-tarfile "$deb" | tar -xO ./conffiles | grep -qx /etc/refocusd.conf ||
  fail "/etc/refocusd.conf is not a conffile"
# The web page: every file of the source's www/ is in the package (the page that web_root's
# default names), and the configuration shows the web settings, commented out (off by default).
for page in "$source_dir"/firmware/web/www/*; do
  grep -qE " \./usr/share/refocusd/www/$(basename "$page")\$" "$work/contents.txt" ||
    fail "the package lacks the web page's $(basename "$page") in /usr/share/refocusd/www"
done
dpkg-deb --fsys-tarfile "$deb" | tar -xO ./etc/refocusd.conf >"$work/refocusd.conf"
for key in web web_token web_root; do
  grep -qE "^# $key = " "$work/refocusd.conf" || fail "/etc/refocusd.conf lacks a commented $key setting"
done
grep -qE "^# web_root = /usr/share/refocusd/www\$" "$work/refocusd.conf" ||
  fail "the configuration's web_root is not where the package puts the page"
depends=$(field Depends)
echo "check_deb: Depends: $depends"

dpkg-deb -x "$deb" "$work/root"
# The package of the release that ships a library, as ROOT's dpkg database says.
owner() {
  dpkg --admindir="$root/var/lib/dpkg" -S "*/$1" 2>/dev/null |
    sed -n "s|^\([^:]*\):$arch: .*/$1\$|\1|p" | head -n1
}
camera_linked=0
for program in refocusd refocus; do
  file=$work/root/usr/bin/$program
  readelf -h "$file" | grep -q "Machine: *$machine" || fail "$program is not an $machine program"
  for lib in $(readelf -d "$file" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
    pkg=$(owner "$lib")
    [[ -n $pkg ]] || fail "$program links $lib, which no package of $root provides"
    [[ ", $depends," == *", $pkg "[\(,]* || ", $depends," == *", $pkg,"* ]] ||
      fail "$program links $lib ($pkg) but Depends lacks $pkg"
    [[ $lib == libcamera.so.* ]] && camera_linked=1
  done
done
((camera_linked)) || fail "refocusd does not link libcamera: the package has no libcamera backend"
out=$("${emulator[@]}" "$work/root/usr/bin/refocusd" --version) || fail "refocusd --version failed"
echo "check_deb: packaged refocusd --version: $out"
[[ $out == "refocusd $version (sensor backends: "*libcamera* ]] ||
  fail "--version does not list the libcamera backend: $out"
conf=$work/root/etc/refocusd.conf
status=0
out=$("${emulator[@]}" "$work/root/usr/bin/refocusd" --check-config --config "$conf" 2>&1) ||
  status=$?
echo "check_deb: packaged configuration (status $status):"
echo "$out"
# A refused line is "refocusd: FILE:LINE: ..."; the checks' lines name a device or a folder.
[[ $out != *"$conf:"[0-9]* ]] || fail "the packaged configuration does not read: $out"
if [[ ! -e /dev/video0 && ! -e /var/lib/refocusd ]]; then
  ((status == 1)) || fail "--check-config passed without /dev/video0 and /var/lib/refocusd"
  [[ $out == *"refocusd: camera /dev/video0: no such device"* ]] ||
    fail "--check-config does not name the missing camera: $out"
  [[ $out == *"refocusd: output folder /var/lib/refocusd: no such file or directory"* ]] ||
    fail "--check-config does not name the missing folder: $out"
fi
mkdir -p "$work/photos"
rm -f "$work/button" && mkfifo "$work/button"
sed -e 's|^backend = v4l2$|backend = synthetic|' -e "s|^button = auto\$|button = $work/button|" \
  -e "s|^output_dir = /var/lib/refocusd\$|output_dir = $work/photos|" "$conf" >"$work/check.conf"
(($(grep -cE "^(backend = synthetic|button = $work/button|output_dir = $work/photos)\$" \
  "$work/check.conf") == 3)) || fail "the packaged configuration lacks the backend, button or output_dir line"
out=$("${emulator[@]}" "$work/root/usr/bin/refocusd" --check-config --config "$work/check.conf" 2>&1) ||
  fail "the packaged configuration with a camera, button and folder at hand is rejected: $out"
[[ $out == "refocusd: sensor backends: "*libcamera*$'\n'"refocusd: $work/check.conf: configuration OK" ]] ||
  fail "unexpected --check-config output: $out"
echo "check_deb: $out"
echo "check_deb: OK"
