#!/bin/bash
# Builds the board's Debian package in a cross build tree and checks it as an installer and the
# board would see it: the four files at their places, the conffile, the architecture, a
# dependency for every library the programs link, and the packaged refocusd running under
# qemu-user: --version, and --check-config, which checks the camera, the button and the photo
# folder besides the file. The packaged configuration must read (no line of it is refused), and
# with its camera, button and folder pointed at ones this machine has (the synthetic camera, a
# FIFO, a new folder) it must pass; where the machine lacks /dev/video0 and /var/lib/refocusd (the
# usual build host) it must name both.
#
#   check_deb.sh BUILD_DIR [EMULATOR ARGS...]
#
# EMULATOR defaults to qemu-aarch64-static with the libraries of build/sysroot/arm64. Exit 0 when
# every check passes, 1 otherwise, 77 (skip) without cpack, dpkg-deb or the emulator.
set -euo pipefail
build=$(cd "${1:?usage: check_deb.sh BUILD_DIR [EMULATOR ARGS...]}" && pwd)
shift
emulator=("$@")

fail() { echo "check_deb: $*" >&2; exit 1; }
cache_value() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }

for tool in cpack dpkg-deb; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool not installed"; exit 77; }
done
version=$(cache_value CMAKE_PROJECT_VERSION)
source_dir=$(cache_value lensblur_SOURCE_DIR)
[[ -n $version && -n $source_dir ]] || fail "$build is not a configured build tree"
if ((${#emulator[@]} == 0)); then
  sysroot=$source_dir/build/sysroot/arm64
  emulator=(qemu-aarch64-static -L /usr/aarch64-linux-gnu -E
            "LD_LIBRARY_PATH=$sysroot/usr/lib/aarch64-linux-gnu:$sysroot/lib/aarch64-linux-gnu")
fi
command -v "${emulator[0]}" >/dev/null || { echo "SKIP: ${emulator[0]} not installed"; exit 77; }

work=$build/deb-check
rm -rf "$work" && mkdir -p "$work"
(cd "$build" && cpack -G DEB -B "$work" >"$work/cpack.log" 2>&1) ||
  { cat "$work/cpack.log"; fail "cpack failed"; }
debs=("$work"/*.deb)
((${#debs[@]} == 1)) || fail "expected one .deb in $work, found ${#debs[@]}"
deb=${debs[0]}
echo "check_deb: $(basename "$deb")"

dpkg-deb -c "$deb" >"$work/contents.txt"
cat "$work/contents.txt"
for entry in "-rwxr-xr-x ./usr/bin/refocusd" "-rwxr-xr-x ./usr/bin/refocus" \
             "-rw-r--r-- ./lib/systemd/system/refocusd.service" "-rw-r--r-- ./etc/refocusd.conf" \
             "-rw-r--r-- ./usr/share/refocusd/www/index.html"; do
  mode=${entry%% *} path=${entry#* }
  grep -qE "^$mode root/root +[0-9]+ [0-9-]+ [0-9:]+ $path\$" "$work/contents.txt" ||
    fail "the package lacks $path with mode $mode owned by root"
done

field() { dpkg-deb -f "$deb" "$1"; }
[[ $(field Package) == refocusd ]] || fail "package name $(field Package), not refocusd"
[[ $(field Architecture) == arm64 ]] || fail "architecture $(field Architecture), not arm64"
[[ $(field Version) == "$version" ]] || fail "version $(field Version), not $version"
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
readelf=$(command -v aarch64-linux-gnu-readelf || command -v readelf)
for program in refocusd refocus; do
  file=$work/root/usr/bin/$program
  "$readelf" -h "$file" | grep -q 'Machine: *AArch64' || fail "$program is not an AArch64 program"
  for lib in $("$readelf" -d "$file" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
    case $lib in
      libc.so.6 | libm.so.6 | ld-linux-aarch64.so.1) pkg=libc6 ;;
      libstdc++.so.6) pkg=libstdc++6 ;;
      libgcc_s.so.1) pkg=libgcc-s1 ;;
      libjpeg.so.62) pkg=libjpeg62-turbo ;;
      libpng16.so.16) pkg=libpng16-16 ;;
      libexif.so.12) pkg=libexif12 ;;
      libmd.so.0) pkg=libmd0 ;;
      libz.so.1) pkg=zlib1g ;;
      libmicrohttpd.so.12) pkg=libmicrohttpd12 ;;
      libcamera.so.* | libcamera-base.so.*) pkg=libcamera0.0.3 ;;
      *) fail "$program links $lib, which no known package provides" ;;
    esac
    [[ ", $depends," == *", $pkg"[\ ,]* ]] || fail "$program links $lib but Depends lacks $pkg"
  done
done

out=$("${emulator[@]}" "$work/root/usr/bin/refocusd" --version) || fail "refocusd --version failed"
echo "check_deb: packaged refocusd --version: $out"
[[ $out == "refocusd $version (sensor backends: "* ]] || fail "unexpected --version output: $out"
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
[[ $out == "refocusd: $work/check.conf: configuration OK" ]] || fail "unexpected --check-config output: $out"
echo "check_deb: $out"
echo "check_deb: OK"
