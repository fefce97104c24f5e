#!/usr/bin/env python3
"""tests/browser/pngcheck.py: pixel checks on chromium screenshots of mech's SVGs.

  pngcheck.py joints SHOT.png FRAME.svg POSITIONS.csv ROW [TOL_PX]
      every point disc of FRAME.svg (drawn with `mech animate --test-colours`)
      is found in SHOT.png by its unique colour; its pixel centroid, mapped
      back through the SVG's data-mech-transform, must be within TOL_PX
      (default 2) pixels of the point's position in row ROW of POSITIONS.csv
      (`mech solve --outputs ... --level positions`).
  pngcheck.py moved A.png B.png FRAME.svg POSITIONS.csv ROW_A ROW_B
      the two screenshots differ around every point that moved by more than
      6 px between the rows, and are identical far from the mechanism.
  pngcheck.py fit SHOT.png ANIM.svg POSITIONS.csv [TOL_PX]
      the row of POSITIONS.csv whose positions best match the discs of a
      screenshot of the animation (--test-colours); prints "row N" last and
      fails when even that row is off by more than TOL_PX (default 3).
  pngcheck.py blank SHOT.png
      fails when the screenshot is one flat colour.

Only the standard library: the PNG decoder below handles what chromium
writes (8-bit RGB or RGBA, not interlaced)."""
import csv
import sys
import struct
import zlib
import xml.dom.minidom


def read_png(path):
    """(width, height, rows of RGB tuples) of an 8-bit RGB/RGBA PNG."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path}: not a PNG")
    pos, idat, w = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or ctype not in (2, 6) or interlace:
                raise SystemExit(f"{path}: PNG depth {depth} type {ctype} not supported")
            bpp = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    raw = zlib.decompress(idat)
    stride = w * bpp
    prev = bytearray(stride)
    rows = []
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * bpp:x * bpp + 3]) for x in range(w)])
        prev = line
    return w, h, rows


def svg_info(path):
    """(s, ox, oy) and {point: '#rrggbb'} of a --test-colours SVG."""
    doc = xml.dom.minidom.parse(path)
    root = doc.documentElement
    s, ox, oy = (float(v) for v in root.getAttribute("data-mech-transform").split())
    colours = {}
    for c in doc.getElementsByTagName("circle"):
        if c.getAttribute("data-point"):
            colours[c.getAttribute("data-point")] = c.getAttribute("fill")
    return (s, ox, oy), colours


_tables = {}


def positions(path, row):
    """{point: (x, y)} in metres from row `row` (0 = first data row) of a CSV."""
    if path not in _tables:
        with open(path) as f:
            _tables[path] = list(csv.reader(f))
    r = _tables[path]
    head = [h.split(" [")[0] for h in r[0]]
    vals = [float(v) for v in r[1 + row]]
    pts = {}
    for i, h in enumerate(head):
        if h.endswith(".x") and h[:-2] + ".y" in head:
            pts[h[:-2]] = (vals[i], vals[head.index(h[:-2] + ".y")])
    return pts


def to_screen(tr, p):
    s, ox, oy = tr
    return ox + s * p[0], oy - s * p[1]


def measure(shot, svg):
    """Pixel centroid and pixel count of each point's disc; the discs wholly
    visible (count at least 80 % of the largest) are marked full."""
    w, h, px = read_png(shot)
    tr, colours = svg_info(svg)
    want = {tuple(int(c[i:i + 2], 16) for i in (1, 3, 5)): n for n, c in colours.items()}
    sums = {n: [0, 0.0, 0.0] for n in colours}
    for y in range(h):
        for x, rgb in enumerate(px[y]):
            name = want.get(rgb)
            if name:
                s = sums[name]
                s[0] += 1
                s[1] += x + 0.5
                s[2] += y + 0.5
    top = max([s[0] for s in sums.values()] + [1])
    meas = {n: (s[1] / s[0], s[2] / s[0], s[0] >= 0.8 * top) for n, s in sums.items() if s[0]}
    return tr, colours, meas


def errors(tr, meas, pts):
    """{point: pixel distance drawn - solved} over the wholly visible discs."""
    out = {}
    for name, (cx, cy, full) in meas.items():
        if full and name in pts:
            sx, sy = to_screen(tr, pts[name])
            out[name] = ((cx - sx) ** 2 + (cy - sy) ** 2) ** 0.5
    return out


def joints(shot, svg, csvfile, row, tol=2.0):
    tr, colours, meas = measure(shot, svg)
    pts = positions(csvfile, row)
    err = errors(tr, meas, pts)
    bad = 0
    for name in sorted(colours):
        if name not in pts:
            print(f"  {name}: not in {csvfile}")
            bad += 1
        elif name not in meas:
            sx, sy = to_screen(tr, pts[name])
            print(f"  {name}: disc not found (colour {colours[name]}, solved at "
                  f"({sx:.1f}, {sy:.1f}) px)")
            bad += 1
        elif name not in err:
            print(f"  {name}: skipped (partly hidden by another disc)")
        else:
            ok = err[name] <= tol
            bad += not ok
            print(f"  {name}: drawn {err[name]:.2f} px from its solved position "
                  f"[{'ok' if ok else 'FAIL'}]")
    if not err:
        print("  no point could be checked")
        bad += 1
    return bad


def fit(shot, svg, csvfile, tol=3.0):
    """The solved row that best matches the drawing (least worst error);
    prints 'row N' last. Fails when even the best row is off by more than tol."""
    tr, colours, meas = measure(shot, svg)
    with open(csvfile) as f:
        nrows = sum(1 for _ in f) - 1
    best = None
    for r in range(nrows):
        err = errors(tr, meas, positions(csvfile, r))
        worst = max(err.values()) if err else float("inf")
        if best is None or worst < best[1]:
            best = (r, worst, len(err))
    r, worst, n = best
    ok = worst <= tol
    print(f"  best row {r}: {n} points, worst {worst:.2f} px [{'ok' if ok else 'FAIL'}]")
    print(f"row {r}")
    return 0 if ok else 1


def moved(a, b, svg, csvfile, ra, rb):
    wa, ha, pa = read_png(a)
    wb, hb, pb = read_png(b)
    if (wa, ha) != (wb, hb):
        print(f"  screenshots differ in size: {wa}x{ha} and {wb}x{hb}")
        return 1
    tr, _ = svg_info(svg)
    A, B = positions(csvfile, ra), positions(csvfile, rb)
    bad, nmoved = 0, 0
    for name in sorted(A):
        p, q = to_screen(tr, A[name]), to_screen(tr, B[name])
        d = ((p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2) ** 0.5
        if d <= 6:
            continue
        nmoved += 1
        diff = 0
        for (x0, y0) in (p, q):
            for y in range(max(0, int(y0) - 4), min(ha, int(y0) + 5)):
                for x in range(max(0, int(x0) - 4), min(wa, int(x0) + 5)):
                    diff += pa[y][x] != pb[y][x]
        status = "ok" if diff > 0 else "FAIL"
        bad += diff == 0
        print(f"  {name}: moved {d:.1f} px, {diff} pixels differ around it [{status}]")
    # far from the mechanism (the bottom-right corner, 8 x 8 px) nothing changes
    same = all(pa[y][x] == pb[y][x] for y in range(ha - 8, ha) for x in range(wa - 8, wa))
    print(f"  corner unchanged: {'ok' if same else 'FAIL'}")
    if nmoved == 0:
        print("  no point moved between the two frames")
        bad += 1
    return bad + (not same)


def blank(shot):
    w, h, px = read_png(shot)
    colours = set()
    for row in px[::4]:
        colours.update(row[::4])
        if len(colours) > 2:
            return 0
    print(f"  {shot}: blank ({len(colours)} colours)")
    return 1


def main(argv):
    if len(argv) >= 5 and argv[1] == "joints":
        bad = joints(argv[2], argv[3], argv[4], int(argv[5]),
                     float(argv[6]) if len(argv) > 6 else 2.0)
    elif len(argv) == 8 and argv[1] == "moved":
        bad = moved(argv[2], argv[3], argv[4], argv[5], int(argv[6]), int(argv[7]))
    elif len(argv) >= 5 and argv[1] == "fit":
        bad = fit(argv[2], argv[3], argv[4], float(argv[5]) if len(argv) > 5 else 3.0)
    elif len(argv) == 3 and argv[1] == "blank":
        bad = blank(argv[2])
    else:
        print(__doc__)
        return 2
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
