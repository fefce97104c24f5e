#!/usr/bin/env python3
"""tests/browser/report_check.py: checks of `mech report` pages rendered by
headless chromium (tests/browser/report.sh).

  report_check.py slider DOM.html SOLVE.csv POSITIONS.csv K SHOT.png
      DOM.html is chromium's --dump-dom of REPORT.html#row=K&test (the page
      moved its slider to K through the slider's input event and wrote what
      it shows into <pre id="mech-test">). Checks:
        - the slider is at K and the page says row K;
        - every value shown equals row K of SOLVE.csv (`mech solve`, same
          options) as a double, bit for bit;
        - every point drawn (the centre of its circle in the page) maps back
          through the animation's data-mech-transform to row K of
          POSITIONS.csv (`mech solve --outputs <all points> --level
          positions`) within 0.15 px of the drawing;
        - SHOT.png (a screenshot of the same page, the animation drawn with
          --test-colours: every point a disc of its own colour): each disc's
          pixel centroid is within 1 px of where row K of POSITIONS.csv puts
          the point.
      Prints "moved NAME X Y" (the measured disc centres) for `moved`.
  report_check.py moved A.txt B.txt MIN_PX
      the disc centres of two `slider` runs: some point moved by more than
      MIN_PX pixels between them (the drawing follows the slider).
  report_check.py play DOM.html SOLVE.csv NROWS
      DOM.html is the --dump-dom of REPORT.html#play&test: Play clicked,
      the page's record written 1 s later. The animation has run (the SMIL
      time of the slider's last update is past 0), the slider has followed
      it (at round(t / duration * (NROWS - 1)), past 0), and the values
      shown are that row of SOLVE.csv, bit for bit. (Where the animation is
      after 1 s depends on the machine's load, so no window is asserted.)
  report_check.py figures DOM.html SHOT.png SCALE NFIG
      the page holds NFIG figures (those of `mech plot`); in SHOT.png (the
      whole page, device scale SCALE) each figure's box is not blank and
      has drawn curves (over 200 pixels of saturated colour), and the
      animation its coloured discs.

Only the standard library (PNG decoding from pngcheck.py)."""
import csv
import html
import json
import os
import re
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pngcheck import read_png  # noqa: E402


def page_report(dom):
    """The JSON the page wrote into <pre id="mech-test">, and the colours of
    the animation's test discs {point: (r, g, b)}."""
    text = open(dom, encoding="utf-8").read()
    m = re.search(r'<pre id="mech-test"[^>]*>(.*?)</pre>', text, re.S)
    if not m or not m.group(1).strip():
        raise SystemExit(f"{dom}: the page wrote no test report (did its script run?)")
    rep = json.loads(html.unescape(m.group(1)))
    colours = {}
    for c in re.finditer(r'<circle r="5" fill="#([0-9a-f]{6})" data-point="([^"]+)"', text):
        colours[c.group(2)] = tuple(int(c.group(1)[i:i + 2], 16) for i in (0, 2, 4))
    return rep, colours


def csv_row(path, k):
    """{column name: float} of data row k (0 = first)."""
    with open(path) as f:
        rows = list(csv.reader(f))
    head = [h.split(" [")[0] for h in rows[0]]
    if k + 1 >= len(rows):
        raise SystemExit(f"{path}: no row {k}")
    return dict(zip(head, (float(v) for v in rows[k + 1])))


def bits(x):
    return struct.pack("<d", x)


def check_values(rep, solve, k):
    want = csv_row(solve, k)
    bad = 0
    for name, v in want.items():
        shown = rep["values"].get(name)
        if shown is None:
            print(f"  {name}: not shown")
            bad += 1
        elif bits(float(shown)) != bits(v):
            print(f"  {name}: shown {shown}, row {k} of {solve} has {v!r} [FAIL]")
            bad += 1
    extra = set(rep["values"]) - set(want)
    if extra:
        print(f"  shown but not in {solve}: {sorted(extra)} [FAIL]")
        bad += 1
    print(f"  {len(want)} values shown equal row {k} of {solve} bit for bit"
          f" [{'ok' if not bad else 'FAIL'}]")
    return bad


def to_page(rep, p):
    """Page pixel of world point p (m): the SVG's transform, then its box."""
    s, ox, oy = (float(v) for v in rep["transform"].split())
    left, top, w, _ = rep["anim"]
    scale = w / rep["width"]
    return left + (ox + s * p[0]) * scale, top + (oy - s * p[1]) * scale


def points_of(positions, k):
    row = csv_row(positions, k)
    return {n[:-2]: (row[n], row[n[:-2] + ".y"]) for n in row
            if n.endswith(".x") and n[:-2] + ".y" in row}


def check_drawn(rep, pts, k):
    """The circles' centres in the page against the solved positions."""
    bad, worst = 0, 0.0
    scale = rep["anim"][2] / rep["width"]
    for name, (cx, cy) in sorted(rep["points"].items()):
        if name not in pts:
            print(f"  {name}: drawn but not in the positions [FAIL]")
            bad += 1
            continue
        x, y = to_page(rep, pts[name])
        err = ((cx - x) ** 2 + (cy - y) ** 2) ** 0.5 / scale  # in SVG px
        worst = max(worst, err)
        if err > 0.15:
            print(f"  {name}: drawn {err:.3f} px from row {k} [FAIL]")
            bad += 1
    missing = set(pts) - set(rep["points"])
    if missing:
        print(f"  not drawn: {sorted(missing)} [FAIL]")
        bad += 1
    print(f"  {len(rep['points'])} points drawn at row {k}'s positions, worst "
          f"{worst:.3f} px [{'ok' if not bad else 'FAIL'}]")
    return bad


def discs(shot, colours):
    """{point: (x, y, pixel count)}: centroids of the discs in a screenshot."""
    w, h, px = read_png(shot)
    want = {rgb: n for n, rgb in colours.items()}
    sums = {}
    for y in range(h):
        for x, rgb in enumerate(px[y]):
            name = want.get(rgb)
            if name:
                s = sums.setdefault(name, [0, 0.0, 0.0])
                s[0] += 1
                s[1] += x + 0.5
                s[2] += y + 0.5
    return {n: (s[1] / s[0], s[2] / s[0], s[0]) for n, s in sums.items()}


def check_pixels(rep, colours, pts, shot, k, tol=1.0):
    found = discs(shot, colours)
    top = max([c for _, _, c in found.values()] + [1])
    bad, checked, worst = 0, 0, 0.0
    for name in sorted(colours):
        if name not in found:
            print(f"  {name}: disc not found in {shot} [FAIL]")
            bad += 1
            continue
        cx, cy, count = found[name]
        print(f"moved {name} {cx:.2f} {cy:.2f}")
        if count < 0.8 * top:
            continue  # partly hidden by another disc
        x, y = to_page(rep, pts[name])
        err = ((cx - x) ** 2 + (cy - y) ** 2) ** 0.5
        checked += 1
        worst = max(worst, err)
        if err > tol:
            print(f"  {name}: disc at ({cx:.1f}, {cy:.1f}), row {k} puts it at "
                  f"({x:.1f}, {y:.1f}): {err:.2f} px [FAIL]")
            bad += 1
    if checked == 0:
        print("  no disc could be checked [FAIL]")
        bad += 1
    print(f"  {checked} discs in the screenshot within {tol} px of row {k}, worst "
          f"{worst:.2f} px [{'ok' if not bad else 'FAIL'}]")
    return bad


def slider(dom, solve, positions, k, shot):
    rep, colours = page_report(dom)
    bad = 0
    if rep["slider"] != k or rep["row"] != k:
        print(f"  slider at {rep['slider']}, row {rep['row']}, not {k} [FAIL]")
        bad += 1
    print(f"  the page says: {rep['where']}")
    bad += check_values(rep, solve, k)
    pts = points_of(positions, k)
    bad += check_drawn(rep, pts, k)
    bad += check_pixels(rep, colours, pts, shot, k)
    return bad


def play(dom, solve, nrows):
    rep, _ = page_report(dom)
    k, t = rep["slider"], float(rep["time"] or "nan")
    want = round(t / rep["duration"] * (rep["frames"] - 1)) if t == t else None
    ok = rep["frames"] == nrows and 0 < k and k == want and rep["row"] == k
    print(f"  playing: the animation at {t:.3f} s of {rep['duration']:g}, the slider at {k}"
          f" (expected {want}) [{'ok' if ok else 'FAIL'}]")
    return (not ok) + check_values(rep, solve, rep["row"])


def moved(a, b, min_px):
    def read(path):
        out = {}
        for line in open(path):
            f = line.split()
            if len(f) == 4 and f[0] == "moved":
                out[f[1]] = (float(f[2]), float(f[3]))
        return out
    pa, pb = read(a), read(b)
    far = max([((pa[n][0] - pb[n][0]) ** 2 + (pa[n][1] - pb[n][1]) ** 2) ** 0.5
               for n in pa if n in pb] + [0.0])
    ok = far > min_px
    print(f"  the drawing moved with the slider: a disc moved {far:.1f} px"
          f" [{'ok' if ok else 'FAIL'}]")
    return 0 if ok else 1


def coloured(px, box, scale):
    """(distinct colours, saturated pixels) inside a page box of a screenshot."""
    left, top, w, h = (v * scale for v in box)
    colours, sat = set(), 0
    for y in range(int(top) + 2, min(len(px), int(top + h) - 2)):
        row = px[y]
        for x in range(int(left) + 2, min(len(row), int(left + w) - 2)):
            rgb = row[x]
            colours.add(rgb)
            sat += max(rgb) - min(rgb) > 30  # a curve, antialiased at scale 0.5
    return len(colours), sat


def figures(dom, shot, scale, nfig):
    rep, _ = page_report(dom)
    w, h, px = read_png(shot)
    bad = 0
    if len(rep["figures"]) != nfig:
        print(f"  the page holds {len(rep['figures'])} figures, mech plot draws {nfig} [FAIL]")
        bad += 1
    for i, box in enumerate([rep["anim"]] + rep["figures"]):
        what = "animation" if i == 0 else f"figure {i}"
        if (box[1] + box[3]) * scale > h + 1:
            print(f"  {what}: below the screenshot ({h} px) [FAIL]")
            bad += 1
            continue
        ncol, sat = coloured(px, box, scale)
        # the animation (--test-colours) is grey but for its discs; a figure's
        # legend alone has under 100 coloured pixels, its curves some hundreds
        ok = ncol > 8 and sat > (50 if i == 0 else 200)
        bad += not ok
        if True:
            print(f"  {what}: {ncol} colours, {sat} coloured pixels [{'ok' if ok else 'FAIL'}]")
    print(f"  {len(rep['figures'])} figures drawn in the page [{'ok' if not bad else 'FAIL'}]")
    return bad


def main(argv):
    if len(argv) == 7 and argv[1] == "slider":
        bad = slider(argv[2], argv[3], argv[4], int(argv[5]), argv[6])
    elif len(argv) == 5 and argv[1] == "play":
        bad = play(argv[2], argv[3], int(argv[4]))
    elif len(argv) == 5 and argv[1] == "moved":
        bad = moved(argv[2], argv[3], float(argv[4]))
    elif len(argv) == 6 and argv[1] == "figures":
        bad = figures(argv[2], argv[3], float(argv[4]), int(argv[5]))
    else:
        print(__doc__)
        return 2
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
