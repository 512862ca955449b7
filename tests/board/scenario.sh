#!/bin/bash
# The emulated board's scenario (board-scenario.service, after multi-user.target). Prints one
# line per check on the console, `BOARD-RESULT NAME ok|FAILED DETAIL`, figures as
# `BOARD-FIGURE NAME VALUE UNIT`, then `BOARD-DONE`; the unit powers the board off when it ends.
# scripts/board.sh reads these lines: every check named in BOARD-PLAN must say ok.
set -u
export LC_ALL=C
plan="package service ready press jpeg depth web_page web_auth web_api web_download check_config stop no_errors"
echo "BOARD-PLAN $plan"
failed=0
photos=/var/lib/refocusd
keys=/run/board/keys
conf=/etc/refocusd.conf
token=$(sed -n 's/^web_token *= *//p' $conf)
url=http://127.0.0.1:8080

ok() { local name=$1; shift; echo "BOARD-RESULT $name ok $*"; }
bad() { local name=$1; shift; echo "BOARD-RESULT $name FAILED $*"; failed=$((failed + 1)); }
figure() { echo "BOARD-FIGURE $*"; }
now() { cut -d' ' -f1 /proc/uptime; }  # seconds since the kernel started
minus() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", a - b }'; }
journal() { journalctl -b -q --no-pager -o cat -u refocusd.service; }
# wait_journal PATTERN SECONDS: until refocusd's journal has a line matching PATTERN.
wait_journal() {
  local end=$(($(date +%s) + $2))
  until journal | grep -q -- "$1"; do
    [ "$(date +%s)" -gt $end ] && return 1
    sleep 0.2
  done
}
whole_jpeg() {
  [ -s "$1" ] && [ "$(head -c 2 "$1" | od -An -tx1 | tr -d ' ')" = ffd8 ] &&
    [ "$(tail -c 2 "$1" | od -An -tx1 | tr -d ' ')" = ffd9 ]
}
# http WHAT URL [curl options]: prints the status; the body goes to /tmp/body.
http() {
  local u=$1; shift
  curl -s -o /tmp/body -w '%{http_code}' --max-time 60 "$@" "$u" || true
}

# package: installed by apt when the image was made, the unit enabled by its postinst.
status=$(dpkg-query -W -f='${Status} ${Version}' refocusd 2>&1)
enabled=$(systemctl is-enabled refocusd.service 2>&1)
fragment=$(systemctl show -P FragmentPath refocusd.service)
depends=$(dpkg-query -W -f='${Depends}' refocusd 2>&1)
case "$status" in
  "install ok installed "*)
    [ "$enabled" = enabled ] && [ "${fragment#/usr}" = /lib/systemd/system/refocusd.service ] &&
      ok package "refocusd ${status##* }, unit $fragment $enabled" ||
      bad package "unit $fragment is $enabled" ;;
  *) bad package "dpkg says: $status" ;;
esac

# ready: systemd started refocusd from the package's unit and it found its camera and button.
if wait_journal 'ready: sensor' 600; then
  at=$(journalctl -b -q --no-pager -o short-monotonic -u refocusd.service |
    grep -m1 'ready: sensor' | sed 's/^\[ *\([0-9.]*\)\].*/\1/')
  ok ready "$(journal | grep -m1 'ready: sensor')"
  figure boot_to_ready "$(minus "$at" 0)" "s (kernel start to refocusd's ready line, journal clock)"
else
  bad ready "no 'ready' from refocusd within 600 s: $(journal | tail -n 3 | tr '\n' '|')"
fi

# service: running as the unit's dynamic user (not root), never restarted.
pid=$(systemctl show -P MainPID refocusd.service)
restarts=$(systemctl show -P NRestarts refocusd.service)
uid=$(awk '/^Uid:/ { print $2 }' /proc/"$pid"/status 2>/dev/null)
user=$(getent passwd "${uid:-0}" | cut -d: -f1)
if [ "$(systemctl is-active refocusd.service)" = active ] && [ -n "$uid" ] && [ "$uid" != 0 ] &&
  [ "$restarts" = 0 ]; then
  ok service "active, pid $pid, user ${user:-$uid} (uid $uid), $restarts restarts"
else
  bad service "$(systemctl is-active refocusd.service), pid $pid, uid ${uid:-none}, $restarts restarts"
fi

# press: KEY_CAMERA from the uinput button -> a photo in the folder.
photo=""
t0=$(now)
if [ -p $keys ] && echo press >$keys; then
  end=$(($(date +%s) + 900))
  until photo=$(ls $photos/IMG_*.jpg 2>/dev/null | head -n1); [ -n "$photo" ]; do
    [ "$(date +%s)" -gt $end ] && break
    sleep 0.1
  done
  t1=$(now)
  if [ -n "$photo" ] && wait_journal 'photo 1: saved' 30; then
    ok press "$(journal | grep -m1 'photo 1: saved')"
    figure press_to_photo "$(minus "$t1" "$t0")" "s (button written to the photo's name in the folder)"
    warn=$(journal | grep -m1 'photo 1: not blurred' || true)
    [ -n "$warn" ] && echo "BOARD-NOTE $warn"
  else
    bad press "no photo within 900 s: $(journal | grep 'press\|photo' | tail -n 3 | tr '\n' '|')"
  fi
else
  bad press "cannot write to the button's FIFO $keys"
fi
name=${photo##*/}

# jpeg: the name holds a whole JPEG, and no temporary stayed behind.
if [ -n "$photo" ] && whole_jpeg "$photo" && ! ls -a $photos | grep -q '^\.IMG_'; then
  ok jpeg "$name: $(wc -c <"$photo") bytes, SOI to EOI, no temporary left"
else
  bad jpeg "${name:-no photo}: not a whole JPEG, or a temporary left: $(ls -a $photos | tr '\n' ' ')"
fi

# depth: the photo carries its depth map; the package's refocus re-renders it from the file alone.
if [ -n "$photo" ] && grep -q 'GDepth:Data' "$photo"; then
  r0=$(now)
  out=$(refocus rerender "$photo" --out /tmp/rerender.jpg --focus 20,20 --f-number 1.4 2>&1)
  code=$?
  r1=$(now)
  if [ $code = 0 ] && whole_jpeg /tmp/rerender.jpg; then
    ok depth "GDepth in the XMP; refocus rerender: $out"
    figure rerender "$(minus "$r1" "$r0")" "s (refocus rerender of the photo)"
  else
    bad depth "refocus rerender exit $code: $out"
  fi
else
  bad depth "${name:-no photo}: no GDepth:Data in the file"
fi

# web_page: the page's files, served without a token.
page=$(http $url/)
js=$(http $url/app.js)
if [ "$page" = 200 ] && [ "$js" = 200 ] && http $url/ >/dev/null && grep -qi '<html' /tmp/body; then
  ok web_page "GET / 200 (html), GET /app.js 200"
else
  bad web_page "GET / $page, GET /app.js $js"
fi

# web_auth: the API refuses a request without the token and one with a wrong token.
none=$(http $url/api/photos)
wrong=$(http $url/api/photos -H "Authorization: Bearer wrong-token-0123456789")
if [ "$none" = 401 ] && [ "$wrong" = 401 ]; then
  ok web_auth "GET /api/photos without a token 401, with a wrong one 401"
else
  bad web_auth "GET /api/photos without a token $none, with a wrong one $wrong"
fi

# web_api: with the token, the photo list names the photo and its info says refocusable.
list=$(http $url/api/photos -H "Authorization: Bearer $token")
listed=no
[ -n "$name" ] && grep -q "\"$name\"" /tmp/body && listed=yes
info=$(http "$url/api/info/$name" -H "Authorization: Bearer $token")
if [ "$list" = 200 ] && [ $listed = yes ] && [ "$info" = 200 ] && grep -q '"refocusable":true' /tmp/body; then
  ok web_api "GET /api/photos 200 lists $name; GET /api/info/$name 200 refocusable"
else
  bad web_api "GET /api/photos $list (listed: $listed), GET /api/info $info: $(head -c 200 /tmp/body)"
fi

# web_download: the photo through the page is the file, byte for byte.
got=$(http "$url/photos/$name" -H "Authorization: Bearer $token")
if [ "$got" = 200 ] && [ -n "$photo" ] && cmp -s /tmp/body "$photo"; then
  ok web_download "GET /photos/$name 200, same bytes as the file"
else
  bad web_download "GET /photos/$name $got, or not the file's bytes"
fi

# check_config: `refocusd --check-config` on the board's file; which sensor backends this build
# has (libcamera: recorded; a failure only if the package depends on libcamera without it).
check=$(refocusd --check-config --config $conf 2>&1)
code=$?
version=$(refocusd --version 2>&1)
libcamera=no
echo "$check $version" | grep -qi libcamera && libcamera=yes
echo "BOARD-NOTE check-config: $(echo "$check" | tr '\n' '|')"
echo "BOARD-NOTE version: $version"
echo "BOARD-NOTE depends: $depends"
detail="exit $code: $(echo "$check" | tail -n1); $version; libcamera listed: $libcamera"
if [ $code != 0 ]; then
  bad check_config "$detail"
elif echo "$depends" | grep -qi libcamera && [ $libcamera = no ]; then
  bad check_config "$detail, but the package depends on libcamera"
else
  ok check_config "$detail"
fi

# stop: SIGTERM from systemd; a clean exit with its summary.
systemctl stop refocusd.service
result=$(systemctl show -P Result refocusd.service)
summary=$(journal | grep 'stopped:' | tail -n1)
if [ "$result" = success ] && echo "$summary" | grep -q 'stopped: 1 photo(s) saved, 0 failed'; then
  ok stop "result $result: $summary"
else
  bad stop "result $result: ${summary:-no 'stopped:' line}"
fi

# no_errors: nothing at priority err or worse from refocusd in this boot.
errors=$(journalctl -b -q --no-pager -o cat -u refocusd.service -p err)
if [ -z "$errors" ]; then
  ok no_errors "refocusd logged no error"
else
  bad no_errors "$(echo "$errors" | head -n 3 | tr '\n' '|')"
fi

echo "BOARD-NOTE systemd-analyze: $(systemd-analyze time 2>&1 | head -n1)"
echo "BOARD-NOTE slowest units: $(systemd-analyze blame --no-pager 2>&1 | head -n 4 | awk '{ $1 = $1; print }' | paste -sd ',' | sed 's/,/, /g')"
journal | sed 's/^/BOARD-LOG /'
echo "BOARD-DONE $failed failed"
[ $failed = 0 ]
