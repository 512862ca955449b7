# VM scenario (run by run_vm.sh with busybox sh): a half press and two quick presses injected
# through uinput reach shutter_job over the kernel's evdev path and become two JPEGs.
set -u
out=/tmp/shots
mkdir -p $out
mkfifo /tmp/keys
uinput_key </tmp/keys >/tmp/keys.node &
exec 3>/tmp/keys
for i in 1 2 3 4 5 6 7 8 9 10; do [ -s /tmp/keys.node ] && break; sleep 0.2; done
node=$(cat /tmp/keys.node)
video=$(grep -l vivid /sys/class/video4linux/video*/name | head -n1 | sed 's|.*/\(video[0-9]*\)/name|/dev/\1|')
echo "scenario: button $node, sensor $video"
shutter_job "$node" "$video" $out 2 &
job=$!
sleep 1
echo half >&3
echo "sleep 300" >&3
echo press >&3
echo "sleep 150" >&3
echo press >&3
echo unhalf >&3
wait $job
status=$?
exec 3>&-
count=$(ls $out/*.jpg 2>/dev/null | wc -l)
echo "scenario: shutter_job exit $status, $count JPEG(s) in $out"
for f in $out/*.jpg; do
  # A whole JPEG starts with FF D8 and ends with FF D9.
  head=$(head -c 2 "$f" | od -An -tx1 | tr -d ' ')
  tail=$(tail -c 2 "$f" | od -An -tx1 | tr -d ' ')
  echo "scenario: $f $(wc -c <"$f") bytes, starts $head, ends $tail"
  [ "$head" = ffd8 ] && [ "$tail" = ffd9 ] || status=1
done
[ $status = 0 ] && [ "$count" = 2 ]
