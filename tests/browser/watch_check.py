#!/usr/bin/env python3
"""tests/browser/watch_check.py: the page of `mech watch` in headless
chromium while its file changes on disk (tests/browser/watch.sh).

  watch_check.py URL FILE DIR CHROMIUM
      DIR holds v1.yaml, v2.yaml and broken.yaml (versions of the watched
      FILE) and, for v1 and v2, solve-vK.csv (`mech solve vK.yaml`) and
      positions-vK.csv (`mech solve --outputs <all points> --level
      positions`). FILE starts as v1. Chromium (no network but 127.0.0.1,
      driven over --remote-debugging-pipe: JSON messages on file
      descriptors 3 and 4, no extra package) opens URL once, then:
        1. the page shows version 1: the values shown are row 0 of
           solve-v1.csv bit for bit, every point is drawn at row 0 of
           positions-v1.csv (within 0.15 px in the DOM; in a screenshot
           each test disc's pixel centroid within 1 px); the slider moved
           to K (its input event) shows row K;
        2. v2 is written to a temporary file renamed over FILE (as editors
           save): the same page shows version 2 within 2 s (the time is
           printed), the slider still at K, with v2's values and positions
           of row K (the slider's script bound to the new drawing), and the
           points moved;
        3. broken.yaml is written over FILE in place: the page shows the
           error as FILE:LINE:COLUMN: error: ... and keeps version 2's
           drawing (the same positions);
        4. v1 again: the drawing is version 1's, at K.

Only the standard library (PNGs decoded by pngcheck.py, the checks shared
with report_check.py)."""
import base64
import json
import os
import re
import select
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report_check import check_drawn, check_pixels, check_values, points_of  # noqa: E402

WAIT_S = 2.0  # the page must follow a save within this (the brief: a second; margin for load)
K = 120       # the slider's position from step 1 on (of 361)


class Chromium:
    """Headless chromium driven through the DevTools protocol on a pipe."""

    def __init__(self, exe, profile, log):
        cmd_r, self.cmd_w = os.pipe()    # our commands: chromium reads fd 3
        self.rep_r, rep_w = os.pipe()    # its replies and events: fd 4
        self.proc = subprocess.Popen(
            ["sh", "-c", f'exec "$0" "$@" 3<&{cmd_r} 4>&{rep_w}', exe, "--headless",
             "--no-sandbox", "--disable-gpu", "--no-proxy-server",
             "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1", "--no-first-run",
             "--disable-extensions", f"--user-data-dir={profile}", "--hide-scrollbars",
             "--force-device-scale-factor=1", "--window-size=1400,1000",
             "--remote-debugging-pipe", "about:blank"],
            pass_fds=(cmd_r, rep_w), stdout=log, stderr=log)
        os.close(cmd_r)
        os.close(rep_w)
        self.buf, self.next_id, self.session = b"", 0, None

    def call(self, method, params=None, timeout=60):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if self.session:
            msg["sessionId"] = self.session
        os.write(self.cmd_w, json.dumps(msg).encode() + b"\0")
        end = time.monotonic() + timeout
        while True:
            while b"\0" in self.buf:
                raw, self.buf = self.buf.split(b"\0", 1)
                reply = json.loads(raw)
                if reply.get("id") == self.next_id:
                    if "error" in reply:
                        raise RuntimeError(f"{method}: {reply['error']}")
                    return reply.get("result", {})
            left = end - time.monotonic()
            if left <= 0 or not select.select([self.rep_r], [], [], left)[0]:
                raise RuntimeError(f"{method}: no reply from chromium in {timeout} s")
            chunk = os.read(self.rep_r, 1 << 20)
            if not chunk:
                raise RuntimeError(f"{method}: chromium closed the pipe")
            self.buf += chunk

    def open(self, url):
        target = self.call("Target.createTarget", {"url": url})["targetId"]
        self.session = self.call("Target.attachToTarget",
                                 {"targetId": target, "flatten": True})["sessionId"]

    def eval(self, expr):
        r = self.call("Runtime.evaluate", {"expression": expr, "returnByValue": True})
        return r.get("result", {}).get("value")

    def screenshot(self, path, width, height):
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})
        data = self.call("Page.captureScreenshot", {"format": "png"})["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))

    def close(self):
        try:
            self.session = None
            self.call("Browser.close", timeout=10)
        except (RuntimeError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


def record(chrome):
    text = chrome.eval("window.mechWatchRecord ? mechWatchRecord() : null")
    return json.loads(text) if text else None


def wait_for(chrome, what, test, timeout):
    """The page's record once test(record) holds; None after timeout s."""
    start = time.monotonic()
    while time.monotonic() - start < timeout:
        rep = record(chrome)
        if rep and test(rep):
            return rep, time.monotonic() - start
        time.sleep(0.02)
    print(f"  {what}: not seen in {timeout} s; the page shows {record(chrome)} [FAIL]")
    return None, timeout


def save_renamed(src, dst):
    """As an editor saves: a temporary file beside dst, renamed over it."""
    tmp = dst + ".tmp~"
    shutil.copyfile(src, tmp)
    os.replace(tmp, dst)


def slide(chrome, k):
    """Move the slider to k as a user does (its input event); the record."""
    chrome.eval(f"var s = document.getElementById('slider'); s.value = {k}; "
                "s.dispatchEvent(new Event('input'));")
    time.sleep(0.2)  # the drawing follows on the next frame
    return record(chrome)


def drawn_as(rep, d, version, k, shot=None, chrome=None):
    """Values and points (DOM) of version `version` at slider position k,
    and with a screenshot, its discs."""
    ok = rep["slider"] == k
    print(f"  the slider is at {rep['slider']} [{'ok' if ok else 'FAIL'}]")
    bad = (not ok) + check_values(rep, f"{d}/solve-v{version}.csv", k)
    pts = points_of(f"{d}/positions-v{version}.csv", k)
    bad += check_drawn(rep, pts, k)
    if not shot:
        return bad
    left, top, w, h = rep["anim"]
    chrome.screenshot(shot, 1400, int(top + h + 20))
    colours = {n: tuple(int(c[i:i + 2], 16) for i in (1, 3, 5))
               for n, c in rep["colours"].items()}
    return bad + check_pixels(rep, colours, pts, shot, k)


def main(argv):
    if len(argv) != 5:
        print(__doc__)
        return 2
    url, path, d, exe = argv[1:]
    log = open(f"{d}/chromium.log", "w")
    chrome = Chromium(exe, f"{d}/chromium-profile", log)
    bad = 0
    try:
        chrome.open(url)
        print("  1. the page, version 1:")
        rep, _ = wait_for(chrome, "version 1", lambda r: r["shown"] == 1, 30)
        if not rep:
            return 1
        bad += drawn_as(rep, d, 1, 0, f"{d}/shot-v1.png", chrome)
        print(f"  the slider moved to {K}:")
        rep = slide(chrome, K)
        bad += drawn_as(rep, d, 1, K)
        first = {n: p for n, p in rep["points"].items()}

        print("  2. v2 saved (a temporary file renamed over the file):")
        save_renamed(f"{d}/v2.yaml", path)
        rep, took = wait_for(chrome, "version 2", lambda r: r["shown"] == 2, 10)
        if not rep:
            return 1
        ok = took <= WAIT_S
        bad += not ok
        print(f"  the page showed version 2 {took:.2f} s after the save"
              f" [{'ok' if ok else 'FAIL'}]")
        bad += drawn_as(rep, d, 2, K, f"{d}/shot-v2.png", chrome)
        far = max(((p[0] - first[n][0]) ** 2 + (p[1] - first[n][1]) ** 2) ** 0.5
                  for n, p in rep["points"].items() if n in first)
        print(f"  the drawing changed: a point moved {far:.1f} px"
              f" [{'ok' if far > 5 else 'FAIL'}]")
        bad += far <= 5

        print("  3. a broken file written in place:")
        shutil.copyfile(f"{d}/broken.yaml", path)
        rep, _ = wait_for(chrome, "the error", lambda r: r["version"] == 3, 10)
        if not rep:
            return 1
        err = rep["error"] or ""
        name = re.escape(path)
        ok = re.search(rf"^{name}:\d+:\d+: error: ", err, re.M) is not None
        print(f"  the page shows: {err.splitlines()[0] if err else '(no error)'}"
              f" [{'ok' if ok else 'FAIL'}]")
        kept = rep["shown"] == 2 and rep["good"] == 2
        print(f"  the drawing kept is version {rep['shown']} [{'ok' if kept else 'FAIL'}]")
        bad += (not ok) + (not kept)
        bad += drawn_as(rep, d, 2, K)
        chrome.screenshot(f"{d}/shot-error.png", 1400, 1000)  # for a look

        print("  4. version 1 again:")
        save_renamed(f"{d}/v1.yaml", path)
        rep, _ = wait_for(chrome, "version 4", lambda r: r["shown"] == 4, 10)
        if not rep:
            return 1
        ok = rep["error"] is None
        print(f"  the error is gone [{'ok' if ok else 'FAIL'}]")
        bad += (not ok) + drawn_as(rep, d, 1, K)
    except RuntimeError as e:
        print(f"  chromium: {e} [FAIL]")
        bad += 1
    finally:
        chrome.close()
        log.close()
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
