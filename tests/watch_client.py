#!/usr/bin/env python3
"""tests/watch_client.py: a client of `mech watch` for tests/watch.sh
(standard library only: urllib, socket).

  watch_client.py serve URL FILE DIR
      FILE is watched by the server at URL, and starts as DIR/v1.yaml. DIR
      also holds v2.yaml, broken.yaml and, for v1 and v2, solve-vK.csv
      (`mech solve`) and positions-vK.csv (`mech solve --outputs <every
      point> --level positions`). Checks, printing one line each:
        - `/` is the page (200, text/html, a Content-Security-Policy,
          well-formed XML, no reference to another host);
        - `/state` is version 1: the rows behind the slider are solve-v1's
          bit for bit, each point of the animation is at row 0 of
          positions-v1 (the drawing rounds to 0.1 px);
        - requests refused: another Host (403), POST (405), paths that try
          to leave (404), headers too long (431), garbage (400), no Host
          (400); a connection that sends nothing does not hold up others;
        - a long poll (/state?since=1) waiting when v2 is saved as editors
          do (a temporary file renamed over FILE) ends within 2 s with
          version 2, whose rows and points are v2's;
        - broken.yaml written in place: version 3 has the error as
          FILE:LINE:COLUMN: error: ... and the last good drawing (2's).
  watch_client.py state URL DIR NAME
      `/state` is a good version 1 whose rows and points are those of
      DIR/solve-NAME.csv and DIR/positions-NAME.csv (mech watch --set
      against mech solve --set).
  watch_client.py closed PORT
      nothing listens on 127.0.0.1:PORT any more."""
import csv
import json
import re
import shutil
import socket
import struct
import sys
import threading
import time
import urllib.error
import urllib.request
import xml.dom.minidom

bad = 0


def check(ok, what):
    global bad
    bad += not ok
    print(f"  {what} [{'ok' if ok else 'FAIL'}]")
    return ok


def fetch(url, timeout=10):
    with urllib.request.urlopen(url, timeout=timeout) as r:
        return r.status, dict(r.headers), r.read().decode("utf-8")


def state(url, since=None, timeout=10):
    q = "" if since is None else f"?since={since}"
    return json.loads(fetch(url + "state" + q, timeout)[2])


def raw(port, data, timeout=5):
    """The status of the answer to raw request bytes."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(data)
        got = b""
        while b"\r\n" not in got:
            chunk = s.recv(4096)
            if not chunk:
                break
            got += chunk
    m = re.match(rb"HTTP/1\.1 (\d{3}) ", got)
    return int(m.group(1)) if m else None


def csv_rows(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return [h.split(" [")[0] for h in rows[0]], [[float(v) for v in r] for r in rows[1:]]


def bits(x):
    return struct.pack("<d", x)


def drawn(st, d, version):
    """The state's rows and points against version `version`'s solves
    (DIR/solve-vVERSION.csv; a name instead of a number: solve-NAME.csv)."""
    html = st["html"]
    # parse_int=float: a value written -0 stays -0.0 (json's int would lose its sign)
    data = json.loads(re.search(r'id="mech-data">(.*?)</script>', html, re.S).group(1),
                      parse_int=float)
    tag = f"v{version}" if isinstance(version, int) else version
    head, rows = csv_rows(f"{d}/solve-{tag}.csv")
    names = [c["name"] for c in data["columns"]]
    same = names == head and all(
        all(bits(v) == bits(w) for v, w in zip(r[1:], rows[int(r[0])])) for r in data["rows"])
    check(same, f"the {len(data['rows'])} rows behind the slider are {tag}'s "
          f"`mech solve` rows bit for bit")
    s, ox, oy = (float(v) for v in re.search(r'data-mech-transform="([^"]+)"', html).group(1)
                 .split())
    phead, prow = csv_rows(f"{d}/positions-{tag}.csv")
    p0 = dict(zip(phead, prow[0]))
    worst, count = 0.0, 0
    for m in re.finditer(r'<g id="anim-P-([^"]+)" transform="translate\(([-0-9.e]+),([-0-9.e]+)\)"',
                         html):
        x, y = ox + s * p0[m.group(1) + ".x"], oy - s * p0[m.group(1) + ".y"]
        worst = max(worst, abs(x - float(m.group(2))), abs(y - float(m.group(3))))
        count += 1
    check(count > 0 and worst <= 0.05 + 1e-9, f"{count} points drawn at row 0 of {tag}'s "
          f"positions (worst {worst:.3f} px; drawn to 0.1 px)")


def page(url):
    status, headers, text = fetch(url)
    check(status == 200 and headers.get("Content-Type", "").startswith("text/html"),
          f"/ is the page ({status}, {headers.get('Content-Type')})")
    csp = headers.get("Content-Security-Policy", "")
    check("default-src 'none'" in csp and "connect-src 'self'" in csp, f"its policy: {csp}")
    try:
        xml.dom.minidom.parseString(text.encode())
        check(True, "the page is well-formed XML")
    except Exception as e:  # noqa: BLE001
        check(False, f"the page is well-formed XML: {e}")
    hosts = set(re.findall(r"(?:https?:)?//([A-Za-z0-9.-]+\.[a-z]{2,})", text)) - {"www.w3.org"}
    check(not hosts and "src=" not in text, f"the page refers to no other host {sorted(hosts)}")


def refused(port):
    host = f"Host: 127.0.0.1:{port}\r\n".encode()
    cases = [
        ("another Host", b"GET / HTTP/1.1\r\nHost: evil.example\r\n\r\n", 403),
        ("another Host with our port", f"GET / HTTP/1.1\r\nHost: evil.example:{port}\r\n\r\n"
         .encode(), 403),
        ("POST", b"POST /state HTTP/1.1\r\n" + host + b"Content-Length: 0\r\n\r\n", 405),
        ("/../etc/passwd", b"GET /../etc/passwd HTTP/1.1\r\n" + host + b"\r\n", 404),
        ("/%2e%2e/etc/passwd", b"GET /%2e%2e/etc/passwd HTTP/1.1\r\n" + host + b"\r\n", 404),
        ("/state/../../etc/passwd", b"GET /state/../../etc/passwd HTTP/1.1\r\n" + host + b"\r\n",
         404),
        ("headers too long", b"GET / HTTP/1.1\r\n" + host + b"X: " + b"a" * 9000 + b"\r\n\r\n",
         431),
        ("a target too long", b"GET /" + b"a" * 2000 + b" HTTP/1.1\r\n" + host + b"\r\n", 414),
        ("garbage", b"\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03\r\n\r\n", 400),
        ("no Host", b"GET / HTTP/1.1\r\n\r\n", 400),
    ]
    for what, data, want in cases:
        got = raw(port, data)
        check(got == want, f"{what}: {got} (expected {want})")
    idle = socket.create_connection(("127.0.0.1", port), timeout=5)  # says nothing
    try:
        t0 = time.monotonic()
        st = state(f"http://127.0.0.1:{port}/", timeout=5)
        check(st["version"] >= 1, f"an idle connection holds nobody up "
              f"(/state in {time.monotonic() - t0:.3f} s)")
    finally:
        idle.close()


def serve(url, path, d):
    port = int(re.match(r"http://127\.0\.0\.1:(\d+)/$", url).group(1))
    page(url)
    st = state(url)
    check(st["version"] == 1 and st["good"] == 1 and st["error"] is None,
          f"/state: version {st['version']}, good {st['good']}, error {st['error']}")
    drawn(st, d, 1)
    refused(port)

    result = {}
    def long_poll():
        t0 = time.monotonic()
        result["state"] = state(url, since=1, timeout=25)
        result["at"] = time.monotonic()
        result["waited"] = time.monotonic() - t0
    poller = threading.Thread(target=long_poll)
    poller.start()
    time.sleep(0.5)
    check("state" not in result, "/state?since=1 waits while the file has not changed")
    saved = time.monotonic()
    shutil.copyfile(f"{d}/v2.yaml", path + ".tmp~")
    shutil.move(path + ".tmp~", path)
    poller.join(25)
    st = result.get("state")
    if not check(st is not None and st["version"] == 2, "the long poll ended with version 2"):
        return
    took = result["at"] - saved
    check(took <= 2.0, f"version 2 came {took:.2f} s after the save")
    check(st["good"] == 2 and st["error"] is None, "version 2 is good")
    drawn(st, d, 2)
    good_html = st["html"]

    shutil.copyfile(f"{d}/broken.yaml", path)  # in place (truncated, written)
    t0 = time.monotonic()
    st = state(url, since=2, timeout=25)
    check(st["version"] == 3, f"the broken file is version 3 ({time.monotonic() - t0:.2f} s)")
    err = st["error"] or ""
    check(re.search(rf"^{re.escape(path)}:\d+:\d+: error: ", err, re.M) is not None,
          f"its error: {err.splitlines()[0] if err else None}")
    check(st["good"] == 2 and st["html"] == good_html, "the last good drawing (2) is kept")


def closed(port):
    try:
        socket.create_connection(("127.0.0.1", int(port)), timeout=2).close()
        check(False, f"nothing listens on 127.0.0.1:{port}")
    except OSError:
        check(True, f"nothing listens on 127.0.0.1:{port}")


def main(argv):
    try:
        if len(argv) == 5 and argv[1] == "serve":
            serve(argv[2], argv[3], argv[4])
        elif len(argv) == 5 and argv[1] == "state":
            st = state(argv[2])
            if check(st["version"] == 1 and st["good"] == 1 and st["error"] is None,
                     f"version 1 is good ({st['version']}, {st['good']}, {st['error']})"):
                drawn(st, argv[3], argv[4])
        elif len(argv) == 3 and argv[1] == "closed":
            closed(argv[2])
        else:
            print(__doc__)
            return 2
    except (OSError, urllib.error.URLError, ValueError, KeyError, AttributeError) as e:
        check(False, f"{type(e).__name__}: {e}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
