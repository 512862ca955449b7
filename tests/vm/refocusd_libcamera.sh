# VM scenario (run by run_vm.sh with busybox sh, --vimc --libcamera): refocusd with the
# libcamera backend on vimc. A half press of a uinput button readies the camera, a press takes a
# 5-frame burst through libcamera and saves a whole JPEG; SIGTERM stops it with exit 0.
set -u
status=0
photos=/tmp/photos
log=/tmp/refocusd.log
ok() { echo "scenario: ok: $*"; }
bad() { echo "scenario: FAILED: $*"; status=1; }
# (0 before the daemon has opened its log: a file not there yet is no match, not an error.)
count() {
  n=$(grep -c "$1" $log 2>/dev/null)
  echo "${n:-0}"
}
wait_for() {  # PATTERN SECONDS
  i=0
  while [ "$(count "$1")" -lt 1 ]; do
    i=$((i + 1))
    [ $i -gt $(($2 * 5)) ] && { bad "no '$1' within $2 s"; return 1; }
    sleep 0.2
  done
  return 0
}

mkdir -p $photos
mkfifo /tmp/keys
uinput_key </tmp/keys >/tmp/keys.node &
exec 3>/tmp/keys
for i in 1 2 3 4 5 6 7 8 9 10; do [ -s /tmp/keys.node ] && break; sleep 0.2; done
node=$(cat /tmp/keys.node)
cat >/tmp/refocusd.conf <<CONF
backend = libcamera
resolution = 640x480
frames = 5
frame_timeout_ms = 5000
button = $node
output_dir = $photos
labels = 12
working_size = 160x120
CONF
refocusd --config /tmp/refocusd.conf 2>$log &
pid=$!
wait_for "ready: sensor" 30
echo half >&3
wait_for "half press: sensor ready" 60 && ok "$(grep 'half press:' $log)"
echo unhalf >&3
echo press >&3
wait_for "photo 1: \(saved\|not saved\)" 180
[ "$(count 'photo 1: saved')" = 1 ] && ok "press through libcamera -> $(ls $photos)" ||
  bad "no photo from libcamera"
kill -TERM $pid
wait $pid
code=$?
[ $code = 0 ] && ok "SIGTERM: exit 0" || bad "SIGTERM: exit $code"
exec 3>&-
for f in $photos/IMG_*.jpg; do
  head=$(head -c 2 "$f" | od -An -tx1 | tr -d ' ')
  tail=$(tail -c 2 "$f" | od -An -tx1 | tr -d ' ')
  [ "$head" = ffd8 ] && [ "$tail" = ffd9 ] && echo "scenario: $f $(wc -c <"$f") bytes, whole" ||
    bad "$f is not a whole JPEG"
done
echo "scenario: refocusd log:"
cat $log
exit $status
