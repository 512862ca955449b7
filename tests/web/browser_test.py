#!/usr/bin/env python3
"""The camera's page in a real browser, against the real refocusd.

refocusd runs with the synthetic sensor, the button as a FIFO and the web page on 127.0.0.1:<a
free port> behind a token. The test presses the button, opens the page in headless Chromium
(Debian's chromium + chromedriver, driven by python3-selenium; nothing is downloaded), logs in,
opens the gallery and the new photo, taps a region at another depth than the photo's focus (found
from the photo's own depth map), waits for the preview and then the full render, and saves. It
checks what a user would see: local sharpness (variance of the Laplacian in a small window,
measured in the page on a canvas) rises at the tap and falls at the old focus, in the preview and
in the saved photo. It keeps a screenshot beside its output and prints the tap -> preview latency.

Exit status 77 (ctest: skipped) when Python's selenium, chromium or chromedriver is absent.
"""

import argparse
import base64
import os
import re
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time
import zlib

SKIP = 77


def skip(why):
    print(f"SKIP: {why}")
    sys.exit(SKIP)


def rss_kib(pid):
    with open(f"/proc/{pid}/status") as f:
        return int(next(line for line in f if line.startswith("VmRSS:")).split()[1])


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


# --- the photo's own depth map and focus (the refocusable JPEG's XMP) -------------------------

def xmp_text(jpeg):
    """Main XMP packet + reassembled extended XMP, as text."""
    main, chunks, pos = b"", {}, 2
    main_sig, ext_sig = b"http://ns.adobe.com/xap/1.0/\0", b"http://ns.adobe.com/xmp/extension/\0"
    while pos + 4 <= len(jpeg) and jpeg[pos] == 0xFF:
        marker = jpeg[pos + 1]
        if marker == 0xDA:
            break
        length = struct.unpack(">H", jpeg[pos + 2:pos + 4])[0]
        payload = jpeg[pos + 4:pos + 2 + length]
        if marker == 0xE1 and payload.startswith(main_sig):
            main = payload[len(main_sig):]
        elif marker == 0xE1 and payload.startswith(ext_sig):
            head = len(ext_sig) + 32
            offset = struct.unpack(">I", payload[head + 4:head + 8])[0]
            chunks[offset] = payload[head + 8:]
        pos += 2 + length
    extended = b"".join(chunks[k] for k in sorted(chunks))
    return (main + extended).decode("utf-8", "replace")


def field(text, name):
    m = re.search(name + r'\s*=\s*"([^"]*)"', text) or re.search(
        "<" + name + r">([^<]*)</" + name + ">", text, re.S)
    return m.group(1) if m else None


def decode_png(data):
    """8/16-bit non-interlaced grey, RGB or RGBA PNG -> (width, height, channels, rows of ints)."""
    pos, idat = 8, b""
    while pos < len(data):
        n = struct.unpack(">I", data[pos:pos + 4])[0]
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            width, height, bits, color = struct.unpack(">IIBB", body[:10])
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    channels = {0: 1, 2: 3, 6: 4}[color]
    raw = zlib.decompress(idat)
    bpp = bits // 8 * channels
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        if kind == 2:
            line = bytearray((v + b) & 255 for v, b in zip(line, prev))
        elif kind != 0:
            for i in range(stride):
                a = line[i - bpp] if i >= bpp else 0
                b, c = prev[i], (prev[i - bpp] if i >= bpp else 0)
                if kind == 1:
                    line[i] = (line[i] + a) & 255
                elif kind == 3:
                    line[i] = (line[i] + (a + b) // 2) & 255
                elif kind == 4:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        step = bits // 8
        rows.append([int.from_bytes(line[i:i + step], "big") for i in range(0, stride, step)])
    return width, height, channels, rows


def depth_map(jpeg):
    """The photo's GDepth as (width, height, rows), and its focus point as fractions."""
    text = xmp_text(jpeg)
    data = field(text, "GDepth:Data")
    if not data:
        raise SystemExit("FAIL: the photo has no GDepth:Data")
    w, h, _, depth = decode_png(base64.b64decode(re.sub(r"\s", "", data)))
    old = (float(field(text, "GFocus:FocalPointX") or 0.5),
           float(field(text, "GFocus:FocalPointY") or 0.5))
    return w, h, depth, old


def pick_tap(jpeg):
    """(old focus, tap): the photo's focus point, and the centre of the most different depth whose
    neighbourhood is uniform, as fractions of the image."""
    w, h, depth, old = depth_map(jpeg)
    fx, fy = int(old[0] * w), int(old[1] * h)
    focus = sorted(depth[y][x] for y in range(max(0, fy - 3), min(h, fy + 4))
                   for x in range(max(0, fx - 3), min(w, fx + 4)))[24]
    best, tap, r = -1, None, max(3, w // 60)
    for y in range(h // 10, h - h // 10, 2):
        for x in range(w // 10, w - w // 10, 2):
            window = [depth[j][i] for j in range(y - r, y + r + 1, max(1, r // 3))
                      for i in range(x - r, x + r + 1, max(1, r // 3))]
            if max(window) - min(window) > 1000:  # of 65535: not one surface
                continue
            diff = abs(depth[y][x] - focus)
            if diff > best:
                best, tap = diff, ((x + 0.5) / w, (y + 0.5) / h)
    if tap is None or best < 6000:
        raise SystemExit(f"FAIL: no region at another depth (best difference {best})")
    return old, tap


# --- the browser side -------------------------------------------------------------------------

SHARPNESS_JS = """
const [src, fx, fy, half, width, done] = arguments;
const img = new Image();
img.onerror = () => done(-1);
img.onload = () => {
  const w = width, h = Math.round(width * img.naturalHeight / img.naturalWidth);
  const canvas = document.createElement('canvas');
  canvas.width = w; canvas.height = h;
  const g = canvas.getContext('2d');
  g.drawImage(img, 0, 0, w, h);
  const d = g.getImageData(0, 0, w, h).data;
  const luma = (x, y) => { const i = 4 * (y * w + x); return 0.299 * d[i] + 0.587 * d[i + 1] + 0.114 * d[i + 2]; };
  const cx = Math.round(fx * w), cy = Math.round(fy * h);
  let n = 0, s = 0, s2 = 0;
  for (let y = Math.max(1, cy - half); y < Math.min(h - 1, cy + half); ++y)
    for (let x = Math.max(1, cx - half); x < Math.min(w - 1, cx + half); ++x) {
      const l = 4 * luma(x, y) - luma(x - 1, y) - luma(x + 1, y) - luma(x, y - 1) - luma(x, y + 1);
      n++; s += l; s2 += l * l;
    }
  done(n ? s2 / n - (s / n) * (s / n) : -1);
};
img.src = src;
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--refocusd", required=True)
    ap.add_argument("--www", required=True)
    ap.add_argument("--out", required=True, help="where the screenshot goes (build tree)")
    ap.add_argument("--resolution", default="2048x1536")
    ap.add_argument("--refocus", help="the command line, to add a photo of a textureless burst "
                    "whose depth the page must call a guess")
    # The latency is a measurement (docs/performance.md, under chrt -f 10), not a pass mark: CI
    # machines are shared, and the renderer runs at low priority by design. A bound given here is
    # checked.
    ap.add_argument("--max-latency-ms", type=float,
                    default=float(os.environ.get("LB_BROWSER_MAX_LATENCY_MS", "inf")))
    args = ap.parse_args()

    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.by import By
        from selenium.webdriver.support.ui import WebDriverWait
    except ImportError:
        skip("python3-selenium is not installed (apt-get install python3-selenium)")
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver_bin = shutil.which("chromedriver")
    if not chromium or not driver_bin:
        skip("chromium and chromium-driver are not installed")

    work = tempfile.mkdtemp(prefix="lb_browser_")
    out_dir, fifo = os.path.join(work, "out"), os.path.join(work, "button")
    os.mkdir(out_dir)
    os.mkfifo(fifo)
    port, token = free_port(), base64.b16encode(os.urandom(16)).decode()
    conf = os.path.join(work, "refocusd.conf")
    with open(conf, "w") as f:
        f.write(f"backend = synthetic\nresolution = {args.resolution}\nbutton = {fifo}\n"
                f"output_dir = {out_dir}\nweb = 127.0.0.1:{port}\nweb_token = {token}\n"
                f"web_root = {os.path.abspath(args.www)}\n")
    log_path = os.path.join(args.out, "browser_refocusd.log")
    log = open(log_path, "w")
    daemon = subprocess.Popen([os.path.abspath(args.refocusd), "--config", conf], stderr=log, stdout=log)
    button = os.open(fifo, os.O_RDWR)
    browser = None
    try:
        deadline = time.time() + 30
        while True:  # the web side listens once the camera is ready
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                if daemon.poll() is not None or time.time() > deadline:
                    raise SystemExit(f"FAIL: refocusd's web side did not start (see {log_path})")
                time.sleep(0.1)

        # The button: KEY_CAMERA down and up, as evdev input_event records.
        t = time.time()
        for value in (1, 0):
            t += 0.1
            sec, usec = int(t), int((t - int(t)) * 1e6)
            os.write(button, struct.pack("llHHi", sec, usec, 1, 212, value) +
                     struct.pack("llHHi", sec, usec, 0, 0, 0))
            time.sleep(0.1)
        deadline, photos = time.time() + 180, []
        while not photos:
            photos = sorted(p for p in os.listdir(out_dir) if p.startswith("IMG_"))
            if time.time() > deadline or daemon.poll() is not None:
                raise SystemExit(f"FAIL: no photo after the button press (see {log_path})")
            time.sleep(0.2)
        name = photos[0]
        with open(os.path.join(out_dir, name), "rb") as f:
            old, tap = pick_tap(f.read())
        print(f"photo {name}: focus at {old[0]:.2f},{old[1]:.2f}; tapping {tap[0]:.2f},{tap[1]:.2f}")

        options = webdriver.ChromeOptions()
        options.binary_location = chromium
        for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1280,1100",
                  "--disable-dev-shm-usage"):
            options.add_argument(a)
        browser = webdriver.Chrome(service=Service(executable_path=driver_bin),
                                   options=options)
        wait = WebDriverWait(browser, 60)
        state = lambda want: wait.until(  # noqa: E731
            lambda b: b.find_element(By.TAG_NAME, "body").get_attribute("data-state") == want)
        browser.get(f"http://127.0.0.1:{port}/")
        state("login")
        browser.find_element(By.ID, "token").send_keys(token)
        browser.find_element(By.CSS_SELECTOR, "#login-form button").click()
        state("gallery")
        thumbs = browser.find_elements(By.CSS_SELECTOR, "#thumbs li")
        assert [li.get_attribute("data-name") for li in thumbs] == [name], "gallery"
        thumbs[0].click()
        state("photo")

        def sharp(src, point, width, half):
            return browser.execute_async_script(SHARPNESS_JS, src, point[0], point[1], half, width)

        img = browser.find_element(By.ID, "photo")
        w, h = img.size["width"], img.size["height"]
        body = lambda b: b.find_element(By.TAG_NAME, "body")  # noqa: E731
        # Three taps (the new point, back to the old focus, the new point again), each after the
        # previous full render is done: the latency of a tap on an idle renderer, best of three
        # (the host is shared), the last tap's preview and render kept for the checks.
        for k, point in enumerate((tap, old, tap), start=1):
            ActionChains(browser).move_to_element_with_offset(
                img, int((point[0] - 0.5) * w), int((point[1] - 0.5) * h)).click().perform()
            wait.until(lambda b: b.execute_script("return window.lbLatencies.length") == k)
            wait.until(lambda b: body(b).get_attribute("data-state") == "rendered")
            if k == 1:
                rss_first = rss_kib(daemon.pid)  # the engine's buffers all touched by now
        latencies = browser.execute_script("return window.lbLatencies")
        latency = min(latencies)
        preview_url = browser.execute_script("return URL.createObjectURL(window.lbPreviewBlob)")
        pw = browser.execute_script(
            "return createImageBitmap(window.lbPreviewBlob).then(b => b.width)")
        original = f"/photos/{name}"
        measures = {}
        measures["preview"] = [sharp(preview_url, p, pw, 8) for p in (tap, old)]
        measures["original at preview size"] = [sharp(original, p, pw, 8) for p in (tap, old)]
        browser.find_element(By.ID, "save").click()
        state("saved")
        saved = browser.find_element(By.TAG_NAME, "body").get_attribute("data-saved-name")
        full_w = int(args.resolution.split("x")[0])
        measures["saved"] = [sharp(f"/photos/{saved}", p, full_w, 12) for p in (tap, old)]
        measures["original"] = [sharp(original, p, full_w, 12) for p in (tap, old)]
        rss_last = rss_kib(daemon.pid)
        os.makedirs(args.out, exist_ok=True)
        shot = os.path.join(args.out, "browser_refocus.png")
        browser.save_screenshot(shot)

        guess_lines = {name: browser.find_element(By.ID, "guess").is_displayed()}
        if args.refocus:
            # A burst with nothing to match: its depth is a guess, and the page says so.
            frames = []
            for k in range(5):
                frames.append(os.path.join(work, f"flat{k}.ppm"))
                with open(frames[-1], "wb") as f:
                    f.write(b"P6\n320 240\n255\n" + bytes([180]) * (320 * 240 * 3))
            flat = "IMG_flat.jpg"
            subprocess.run([os.path.abspath(args.refocus), "run", "--geometry", "rectified",
                            "--labels", "16", *frames, "--out", os.path.join(out_dir, flat)],
                           check=True, capture_output=True)
            browser.find_element(By.ID, "back").click()
            state("gallery")
            thumb = f'#thumbs li[data-name="{flat}"]'
            wait.until(lambda b: b.find_elements(By.CSS_SELECTOR, thumb))
            browser.find_element(By.CSS_SELECTOR, thumb).click()
            state("photo")
            guess_lines[flat] = browser.find_element(By.ID, "guess").is_displayed()

        for k, (at_tap, at_old) in measures.items():
            print(f"sharpness {k:>26}: at the tap {at_tap:8.1f}, at the old focus {at_old:8.1f}")
        print(f"tap -> preview shown: best {latency:.0f} ms of "
              f"{', '.join(f'{v:.0f}' for v in latencies)} ms (preview {pw} px wide); "
              f"saved {saved}; screenshot {shot}")
        failures = []
        for got, ref in (("preview", "original at preview size"), ("saved", "original")):
            if not measures[got][0] > 1.3 * measures[ref][0]:
                failures.append(f"{got}: not sharper at the tap than the original")
            if not measures[got][1] < 0.8 * measures[ref][1]:
                failures.append(f"{got}: not softer at the old focus than the original")
        if saved == name or not os.path.exists(os.path.join(out_dir, saved)):
            failures.append(f"saved as '{saved}': not a new photo in the folder")
        if latency > args.max_latency_ms:
            failures.append(f"tap -> preview {latency:.0f} ms > {args.max_latency_ms:.0f} ms")
        print(f"refocusd resident: {rss_first / 1024:.1f} MiB after the first render, "
              f"{rss_last / 1024:.1f} MiB after three more renders and a save")
        if rss_last - rss_first > 8 * 1024:
            failures.append("refocusd's memory grew by more than 8 MiB")
        print("the page's guess line: " + ", ".join(f"{k} {'shown' if v else 'hidden'}"
                                                      for k, v in guess_lines.items()))
        if guess_lines[name]:
            failures.append(f"{name}: a textured scene's depth called a guess")
        if args.refocus and not guess_lines.get("IMG_flat.jpg"):
            failures.append("IMG_flat.jpg: a textureless burst's depth not called a guess")
        if daemon.poll() is not None:
            failures.append("refocusd ended")
        for f in failures:
            print("FAIL:", f)
        return 1 if failures else 0
    finally:
        if browser is not None:
            browser.quit()
        daemon.terminate()
        try:
            daemon.wait(timeout=20)
        except subprocess.TimeoutExpired:
            daemon.kill()
        os.close(button)
        log.close()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
