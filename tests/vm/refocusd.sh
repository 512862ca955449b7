# VM scenario (run by run_vm.sh with busybox sh): the refocusd daemon on real drivers. It starts
# before its camera (vivid unloaded): it says the node is missing and that it is not ready,
# refuses a press with that reason, and finds vivid once it is loaded. Presses of a uinput
# KEY_CAMERA button reach it through evdev (a half press readies the sensor, a press while busy
# is queued); the V4L2 sensor takes 5-frame bursts from vivid. Then the faults, each followed by
# a press that must succeed: the sensor stops delivering (vivid drops every buffer: timeout),
# frames are dropped (vivid drops half), the photo folder (a 1 MiB tmpfs) is full. Ends with
# SIGTERM: exit 0. Every photo name must hold a whole JPEG, and no temporary may stay behind.
set -u
status=0
photos=/photos
log=/tmp/refocusd.log
ok() { echo "scenario: ok: $*"; }
bad() { echo "scenario: FAILED: $*"; status=1; }

# count PATTERN: lines of the log matching PATTERN.
# (0 before the daemon has opened its log: a file not there yet is no match, not an error.)
count() {
  n=$(grep -c "$1" $log 2>/dev/null)
  echo "${n:-0}"
}
# wait_for PATTERN N SECONDS: until the log has N lines matching PATTERN.
wait_for() {
  i=0
  while [ "$(count "$1")" -lt "$2" ]; do
    i=$((i + 1))
    [ $i -gt $(($3 * 5)) ] && { bad "no '$1' (x$2) within $3 s"; return 1; }
    sleep 0.2
  done
  return 0
}
# A photo ended, either way: "photo N: saved" or "photo N: not saved".
wait_photo() { wait_for "photo $1: \(saved\|not saved\)" 1 180; }
whole_jpeg() {
  head=$(head -c 2 "$1" | od -An -tx1 | tr -d ' ')
  tail=$(tail -c 2 "$1" | od -An -tx1 | tr -d ' ')
  [ "$head" = ffd8 ] && [ "$tail" = ffd9 ]
}
photo_count() { ls $photos | grep -c '^IMG_.*\.jpg$' || true; }
temp_count() { ls -a $photos | grep -c '^\.IMG_' || true; }

mkdir -p $photos
mount -t tmpfs -o size=1m photos $photos || bad "cannot mount the small photo folder"
mkfifo /tmp/keys
uinput_key </tmp/keys >/tmp/keys.node &
exec 3>/tmp/keys
for i in 1 2 3 4 5 6 7 8 9 10; do [ -s /tmp/keys.node ] && break; sleep 0.2; done
node=$(cat /tmp/keys.node)
vivid_node() {
  grep -l vivid /sys/class/video4linux/video*/name 2>/dev/null | head -n1 |
    sed 's|.*/\(video[0-9]*\)/name|/dev/\1|'
}
video=$(vivid_node)
echo "scenario: button $node, sensor $video"
# The camera is plugged in after the daemon started: vivid unloaded until then.
rmmod vivid || bad "cannot unload vivid"
[ -e "$video" ] && bad "$video still there without vivid"
cat >/tmp/refocusd.conf <<EOF
backend = v4l2
device = $video
resolution = 320x180
frames = 5
fps = 5
frame_timeout_ms = 1500
button = $node
output_dir = $photos
labels = 12
working_size = 160x120
log_level = debug
EOF
refocusd --config /tmp/refocusd.conf 2>$log &
pid=$!

# 0. No camera yet: a clear line, not ready, a press refused with the reason; then vivid loads.
wait_for "not ready: will check again in 1 s" 1 30 &&
  [ "$(count "error: camera $video: no such device")" = 1 ] && [ "$(count 'ready: sensor')" = 0 ] &&
  ok "started without its camera: $(grep -m1 'camera ' $log)" || bad "no 'not ready' for the missing camera"
echo press >&3
wait_for "press: refused, not ready: camera $video: no such device" 1 30 && ok "press while not ready: refused"
insmod $(grep '/vivid.ko' /modules.list) || bad "cannot load vivid again"
[ "$(vivid_node)" = "$video" ] || bad "vivid came back as '$(vivid_node)', not $video"
wait_for "ready: sensor v4l2 $video" 1 60 && [ "$(count 'the camera is there now')" = 1 ] &&
  ok "camera plugged in later: found" || bad "vivid loaded later was not found"

# 1. A half press readies the sensor; a press: a 5-frame burst from vivid becomes a JPEG.
echo half >&3
wait_for "half press: sensor ready" 1 30 && ok "half press: $(grep 'half press:' $log)"
echo unhalf >&3
echo press >&3
wait_photo 1 && [ "$(count 'photo 1: saved')" = 1 ] && [ "$(photo_count)" = 1 ] &&
  ok "press -> $(ls $photos)" || bad "the first press gave no photo"

# A second press while the first is being taken is queued, and its photo follows.
echo press >&3
echo "sleep 300" >&3
echo press >&3
wait_photo 3
[ "$(count 'press during photo 2 .*: queued')" = 1 ] && [ "$(count 'photo 3: saved')" = 1 ] &&
  ok "press while busy: queued and saved" || bad "press while busy: not queued and saved"

# 2. The sensor stops delivering: a timeout, then the next press works.
v4l2_ctrl $video "Percentage of Dropped Buffers" 100
echo press >&3
wait_photo 4
[ "$(count 'photo 4: not saved: .*no frame within 1500 ms')" = 1 ] && ok "stalled sensor: timeout logged" ||
  bad "stalled sensor: no timeout logged"
v4l2_ctrl $video "Percentage of Dropped Buffers" 0
echo press >&3
wait_photo 5 && [ "$(count 'photo 5: saved')" = 1 ] && ok "after the timeout: photo 5 saved" ||
  bad "after the timeout: photo 5 not saved"

# 3. Dropped frames: with half of vivid's buffers dropped, a burst of 5 survives 1 time in 16 and
# a photo gets a second burst; three presses see a drop but for odds of 1 in 16.7 million.
v4l2_ctrl $video "Percentage of Dropped Buffers" 50
n=5
for try in 1 2 3; do
  n=$((n + 1))
  echo press >&3
  wait_photo $n
  [ "$(count 'frame(s) dropped')" -gt 0 ] && break
done
[ "$(count 'frame(s) dropped')" -gt 0 ] && ok "dropped frames logged: $(grep -m1 'frame(s) dropped' $log)" ||
  bad "no dropped frame seen"
v4l2_ctrl $video "Percentage of Dropped Buffers" 0
n=$((n + 1))
echo press >&3
wait_photo $n && [ "$(count "photo $n: saved")" = 1 ] && ok "after the drops: photo $n saved" ||
  bad "after the drops: photo $n not saved"

# 4. The photo folder is full: no photo, no temporary, a clear line; then room again.
before=$(photo_count)
dd if=/dev/zero of=$photos/filler bs=4k 2>/dev/null
n=$((n + 1))
echo press >&3
wait_photo $n
[ "$(count "photo $n: not saved: .*: no space left on device")" = 1 ] && ok "full folder logged" ||
  bad "full folder: no 'no space left on device' line"
[ "$(photo_count)" = "$before" ] && [ "$(temp_count)" = 0 ] && ok "full folder: nothing left behind" ||
  bad "full folder: $(photo_count) photos (was $before), $(temp_count) temporaries"
rm $photos/filler
n=$((n + 1))
echo press >&3
wait_photo $n && [ "$(count "photo $n: saved")" = 1 ] && ok "with room again: photo $n saved" ||
  bad "with room again: photo $n not saved"

# 5. SIGTERM: a clean stop.
kill -TERM $pid
wait $pid
code=$?
[ $code = 0 ] && [ "$(count 'stopped:')" = 1 ] && ok "SIGTERM: exit 0" || bad "SIGTERM: exit $code"
exec 3>&-

for f in $photos/IMG_*.jpg; do
  whole_jpeg "$f" && echo "scenario: $f $(wc -c <"$f") bytes, whole" || bad "$f is not a whole JPEG"
done
[ "$(temp_count)" = 0 ] || bad "temporaries left: $(ls -a $photos)"
echo "scenario: refocusd log:"
cat $log
echo "scenario: $(photo_count) photos, status $status"
exit $status
