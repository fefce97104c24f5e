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
  pngcheck.py path SHOT.png FIG.svg POSITIONS.csv POINT [TOL_PX]
      a path figure (`mech plot`, path-POINT.svg): the pixels of the curve's
      colour in the plot area lie within TOL_PX (default 1.5) of the solved
      positions of POINT (every row of POSITIONS.csv, joined in order)
      mapped through the SVG's data-mech-transform, and every solved position
      has such a pixel within TOL_PX; the start marker and the arrows (their
      data-at) are left out, 9 px around.
  pngcheck.py scalebar SHOT.png ANIM.svg
      the scale bar of a --test-colours animation (colour #00a0ff) is drawn
      as long as its label says, at the SVG's data-mech-transform, within
      1 px.
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


def curve_alpha(rgb, colour):
    """How much of `colour` over white a pixel is (0..1), or None when its
    channels disagree (another colour: grid, text, a blend with those)."""
    a = [(255 - p) / (255 - c) for p, c in zip(rgb, colour) if 255 - c > 60]
    if not a or max(a) - min(a) > 0.15:
        return None
    return sum(a) / len(a)


class Segments:
    """The polyline through pts, bucketed on a grid of `cell` px, for the
    distance from a pixel to it."""

    def __init__(self, pts, cell=8.0):
        self.cell, self.grid = cell, {}
        for a, b in zip(pts, pts[1:]):
            x0, x1 = sorted((a[0], b[0]))
            y0, y1 = sorted((a[1], b[1]))
            for i in range(int(x0 // cell), int(x1 // cell) + 1):
                for j in range(int(y0 // cell), int(y1 // cell) + 1):
                    self.grid.setdefault((i, j), []).append((a, b))

    def dist(self, x, y):
        best = float("inf")
        i0, j0 = int(x // self.cell), int(y // self.cell)
        for i in (i0 - 1, i0, i0 + 1):
            for j in (j0 - 1, j0, j0 + 1):
                for (a, b) in self.grid.get((i, j), ()):
                    vx, vy = b[0] - a[0], b[1] - a[1]
                    l2 = vx * vx + vy * vy
                    u = ((x - a[0]) * vx + (y - a[1]) * vy) / l2 if l2 else 0.0
                    u = min(1.0, max(0.0, u))
                    best = min(best, ((x - a[0] - u * vx) ** 2 + (y - a[1] - u * vy) ** 2) ** 0.5)
        return best


def path(shot, svg, csvfile, point, tol=1.5):
    w, h, px = read_png(shot)
    doc = xml.dom.minidom.parse(svg)
    root = doc.documentElement
    tr = tuple(float(v) for v in root.getAttribute("data-mech-transform").split())
    x0, y0, x1, y1 = (float(v) for v in root.getAttribute("data-mech-plot").split())
    colour = None  # the first curve: the first path of the group clipped to the plot
    for g in doc.getElementsByTagName("g"):
        if g.getAttribute("clip-path") and colour is None:
            e = g.getElementsByTagName("path")[0]
            colour = tuple(int(e.getAttribute("stroke")[i:i + 2], 16) for i in (1, 3, 5))
    marks = []
    for e in doc.getElementsByTagName("use"):
        if e.getAttribute("data-at"):
            marks.append(tuple(float(v) for v in e.getAttribute("data-at").split(",")))
    with open(csvfile) as f:
        rows = list(csv.reader(f))
    head = [c.split(" [")[0] for c in rows[0]]
    ix, iy = head.index(point + ".x"), head.index(point + ".y")
    pts = [to_screen(tr, (float(r[ix]), float(r[iy]))) for r in rows[1:]]
    near_mark = lambda x, y: any((x - m[0]) ** 2 + (y - m[1]) ** 2 < 81 for m in marks)
    inside = lambda x, y: x0 + 2 <= x <= x1 - 2 and y0 + 2 <= y <= y1 - 2
    line = Segments(pts)
    curve, worst, bad = [], 0.0, 0
    for y in range(int(y0) + 2, int(y1) - 1):
        for x in range(int(x0) + 2, int(x1) - 1):
            a = curve_alpha(px[y][x], colour)
            if a is None or a < 0.5 or near_mark(x + 0.5, y + 0.5):
                continue
            curve.append((x + 0.5, y + 0.5))
            d = line.dist(x + 0.5, y + 0.5)
            worst = max(worst, d)
            bad += d > tol
    print(f"  {len(curve)} curve pixels, farthest {worst:.2f} px from the solved path "
          f"({bad} beyond {tol} px) [{'ok' if bad == 0 and curve else 'FAIL'}]")
    grid = {}
    for c in curve:
        grid.setdefault((int(c[0] // 4), int(c[1] // 4)), []).append(c)
    missing, checked = 0, 0
    for (x, y) in pts[::max(1, len(pts) // 2000)]:
        if not inside(x, y) or near_mark(x, y):
            continue
        checked += 1
        i0, j0 = int(x // 4), int(y // 4)
        d = min([((x - c[0]) ** 2 + (y - c[1]) ** 2) ** 0.5 for i in (i0 - 1, i0, i0 + 1)
                 for j in (j0 - 1, j0, j0 + 1) for c in grid.get((i, j), ())] + [float("inf")])
        missing += d > tol
    print(f"  {checked} solved positions, {missing} without a curve pixel within {tol} px "
          f"[{'ok' if missing == 0 and checked else 'FAIL'}]")
    return (bad > 0) + (not curve) + (missing > 0) + (checked == 0)


def scalebar(shot, svg):
    w, h, px = read_png(shot)
    doc = xml.dom.minidom.parse(svg)
    s = float(doc.documentElement.getAttribute("data-mech-transform").split()[0])
    bar = None
    for g in doc.getElementsByTagName("g"):
        if g.getAttribute("data-mech-scale-bar"):
            bar = g
    metres, bx0, bx1, by = (float(v) for v in bar.getAttribute("data-mech-scale-bar").split())
    label = bar.getElementsByTagName("text")[0].firstChild.data
    mm = float(label.split()[0])
    want = mm * 1e-3 * s
    xs = [x for y in range(int(by) - 1, int(by) + 2) for x in range(w) if px[y][x] == (0, 160, 255)]
    if not xs:
        print("  scale bar: no pixel of its colour #00a0ff")
        return 1
    got = max(xs) - min(xs) + 1
    ok = abs(got - want) <= 1 and abs(metres - mm * 1e-3) < 1e-12
    print(f"  scale bar '{label}': drawn {got} px, {mm} mm at {s:.6g} px/m is {want:.2f} px "
          f"[{'ok' if ok else 'FAIL'}]")
    return 0 if ok else 1


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
    elif len(argv) >= 6 and argv[1] == "path":
        bad = path(argv[2], argv[3], argv[4], argv[5], float(argv[6]) if len(argv) > 6 else 1.5)
    elif len(argv) == 4 and argv[1] == "scalebar":
        bad = scalebar(argv[2], argv[3])
    elif len(argv) == 3 and argv[1] == "blank":
        bad = blank(argv[2])
    else:
        print(__doc__)
        return 2
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
