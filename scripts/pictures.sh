#!/usr/bin/env bash
# The README's pictures of what the product does, from the synthetic scene alone (no third-party
# images): the burst's reference frame, its depth (near light, far dark), the photo refocused
# near and far, and the web page after a tap. 480 px wide JPEGs in docs/pictures/, small enough
# to keep the clone light. Needs a host build (refocus, refocusd) and, for the page, Debian's
# python3-selenium, chromium and chromium-driver (without them the page picture is left as is).
#   bash scripts/pictures.sh [BUILD_DIR]       (default build/host)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build/host}
out=$root/docs/pictures
refocus=$build/firmware/refocus
refocusd=$build/firmware/refocusd
for tool in "$refocus" /usr/bin/djpeg /usr/bin/cjpeg; do
  [ -x "$tool" ] || { echo "pictures: $tool missing (cmake --build --preset host; bash scripts/setup.sh)"; exit 1; }
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"

# One synthetic shot at 1920x1440 (a quarter is 480 px wide), focused at its default centre.
"$refocus" run --synthetic --resolution 1920x1440 --out "$tmp/shot.jpg" >/dev/null
# Its all-in-focus original (the reference frame, stored as GImage), its depth as a grey PGM at
# 480 px, and the nearest and farthest surfaces (uniform depth around them) to focus on.
read -r near far < <(/usr/bin/python3 - "$tmp" "$root/tests/web" <<'PY'
import base64, re, sys
tmp, tests = sys.argv[1], sys.argv[2]
sys.path.insert(0, tests)
import browser_test as bt
jpeg = open(f"{tmp}/shot.jpg", "rb").read()
text = bt.xmp_text(jpeg)
open(f"{tmp}/reference.jpg", "wb").write(
    base64.b64decode(re.sub(r"\s", "", bt.field(text, "GImage:Data"))))
w, h, depth, _ = bt.depth_map(jpeg)
ow, oh = 480, 480 * h // w
with open(f"{tmp}/depth.pgm", "wb") as f:  # RangeInverse: 0 is near; shown near = light
    f.write(b"P5 %d %d 255\n" % (ow, oh))
    f.write(bytes(255 - depth[y * h // oh][x * w // ow] // 257 for y in range(oh) for x in range(ow)))
extremes, r = {}, max(3, w // 60)
for y in range(h // 8, h - h // 8, 2):
    for x in range(w // 8, w - w // 8, 2):
        win = [depth[j][i] for j in range(y - r, y + r + 1, 2) for i in range(x - r, x + r + 1, 2)]
        if max(win) - min(win) > 1000:
            continue
        v = depth[y][x]
        if "near" not in extremes or v < extremes["near"][0]:
            extremes["near"] = (v, x, y)
        if "far" not in extremes or v > extremes["far"][0]:
            extremes["far"] = (v, x, y)
print(" ".join(f"{e[1] * 1920 // w},{e[2] * 1440 // h}" for e in (extremes["near"], extremes["far"])))
PY
)
"$refocus" rerender "$tmp/shot.jpg" --focus "$near" --f-number 2 --out "$tmp/near.jpg" >/dev/null
"$refocus" rerender "$tmp/shot.jpg" --focus "$far" --f-number 2 --out "$tmp/far.jpg" >/dev/null
small() { /usr/bin/djpeg -scale 1/4 "$1" | /usr/bin/cjpeg -quality 85 -optimize >"$2"; }
small "$tmp/reference.jpg" "$out/reference.jpg"
/usr/bin/cjpeg -quality 90 -optimize "$tmp/depth.pgm" >"$out/depth.jpg"
small "$tmp/near.jpg" "$out/focus_near.jpg"
small "$tmp/far.jpg" "$out/focus_far.jpg"
echo "pictures: near focus at $near, far at $far (of 1920x1440)"

# The page after a tap, from the browser test's screenshot.
if [ -x "$refocusd" ] && /usr/bin/python3 "$root/tests/web/browser_test.py" --refocusd "$refocusd" \
  --www "$root/firmware/web/www" --out "$tmp" >"$tmp/browser.log" 2>&1; then
  /usr/bin/python3 - "$tmp" "$root/tests/web" <<'PY'
import sys
tmp, tests = sys.argv[1], sys.argv[2]
sys.path.insert(0, tests)
import browser_test as bt
w, h, c, rows = bt.decode_png(open(f"{tmp}/browser_refocus.png", "rb").read())
ow, oh = 480, 480 * h // w
with open(f"{tmp}/page.ppm", "wb") as f:
    f.write(b"P6 %d %d 255\n" % (ow, oh))
    out = bytearray()
    for y in range(oh):  # the mean of each output pixel's block: text stays legible
        ys = range(y * h // oh, max(y * h // oh + 1, (y + 1) * h // oh))
        for x in range(ow):
            xs = range(x * w // ow, max(x * w // ow + 1, (x + 1) * w // ow))
            n = len(ys) * len(xs)
            for k in range(3):
                out.append(sum(rows[j][i * c + k] for j in ys for i in xs) // n)
    f.write(bytes(out))
PY
  /usr/bin/cjpeg -quality 85 -optimize "$tmp/page.ppm" >"$out/page.jpg"
else
  echo "pictures: no page screenshot (browser test: $(tail -1 "$tmp/browser.log"))"
fi
ls -l "$out"
