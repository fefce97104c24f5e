#!/usr/bin/env python3
"""tests/drawn/truth.py: a drawn mechanism's solved rows against its
construction by circle and line intersections, written independently of
mech: python3 truth.py FILE.yaml ROWS.csv. The file's '# truth:' comment
lines give the construction, in order, each placing one point from the
drawing's dimensions (mm in the file; the CSV is in SI):

  crank P O            P = O + |OP| (cos q, sin q)      (q: the driver angle)
  slide P T DEG        P = T + q (cos DEG, sin DEG)     (q: the driver displacement)
  dyad P A B           P on the circles (A, |AP|) and (B, |BP|), on the
                       side of A -> B that the drawing puts it
  line P A G DEG       P on the circle (A, |AP|) and the line through G at
                       DEG, on the side of A's foot that the drawing puts it
  rigid P A B          P fixed in the frame A -> B as drawn
  moves P R            P keeps its drawn offset from R (a sliding block)

Exits 1 and prints the first row and point that differ by more than 1e-9 m."""
import csv
import math
import re
import sys

import yaml


def drawing_of(doc):
    pts = {}
    for name, (x, y) in doc["drawing"].items():
        pts[name] = (float(x) * 1e-3, float(y) * 1e-3)
    return pts


def construct(steps, drawn, q):
    p = {}
    for g in ground_points:
        p[g] = drawn[g]
    for s in steps:
        kind, name = s[0], s[1]
        if kind == "crank":
            o = p[s[2]]
            r = math.dist(drawn[name], drawn[s[2]])
            p[name] = (o[0] + r * math.cos(q), o[1] + r * math.sin(q))
        elif kind == "slide":
            t, a = p[s[2]], math.radians(float(s[3]))
            p[name] = (t[0] + q * math.cos(a), t[1] + q * math.sin(a))
        elif kind == "dyad":
            a, b = p[s[2]], p[s[3]]
            ra, rb = math.dist(drawn[name], drawn[s[2]]), math.dist(drawn[name], drawn[s[3]])
            da, db, dp = drawn[s[2]], drawn[s[3]], drawn[name]
            side = math.copysign(1, (db[0] - da[0]) * (dp[1] - da[1]) - (db[1] - da[1]) * (dp[0] - da[0]))
            d = math.dist(a, b)
            ux, uy = (b[0] - a[0]) / d, (b[1] - a[1]) / d
            x = (ra * ra - rb * rb + d * d) / (2 * d)
            h = math.sqrt(max(ra * ra - x * x, 0.0))
            p[name] = (a[0] + x * ux - side * h * uy, a[1] + x * uy + side * h * ux)
        elif kind == "line":
            a, g, ang = p[s[2]], p[s[3]], math.radians(float(s[4]))
            r = math.dist(drawn[name], drawn[s[2]])
            ux, uy = math.cos(ang), math.sin(ang)
            da, dp = drawn[s[2]], drawn[name]
            side = math.copysign(1, (dp[0] - da[0]) * ux + (dp[1] - da[1]) * uy)
            t = (a[0] - g[0]) * ux + (a[1] - g[1]) * uy          # A's foot on the line
            fx, fy = g[0] + t * ux, g[1] + t * uy
            off = math.hypot(a[0] - fx, a[1] - fy)
            along = math.sqrt(max(r * r - off * off, 0.0))
            p[name] = (fx + side * along * ux, fy + side * along * uy)
        elif kind == "rigid":
            a, b = p[s[2]], p[s[3]]
            da, db, dp = drawn[s[2]], drawn[s[3]], drawn[name]
            th = math.atan2(b[1] - a[1], b[0] - a[0]) - math.atan2(db[1] - da[1], db[0] - da[0])
            vx, vy = dp[0] - da[0], dp[1] - da[1]
            p[name] = (a[0] + vx * math.cos(th) - vy * math.sin(th),
                       a[1] + vx * math.sin(th) + vy * math.cos(th))
        elif kind == "moves":
            r, dr, dp = p[s[2]], drawn[s[2]], drawn[name]
            p[name] = (r[0] + dp[0] - dr[0], r[1] + dp[1] - dr[1])
        else:
            raise SystemExit("unknown truth step " + kind)
    return p


text = open(sys.argv[1]).read()
doc = yaml.safe_load(text)
drawn = drawing_of(doc)
ground_points = doc["ground"]
steps = [line.split()[2:] for line in text.splitlines() if line.startswith("# truth:")]
steps = [s for s in steps if s]
rows = list(csv.reader(open(sys.argv[2])))
head = [re.sub(r" \[.*\]$", "", h) for h in rows[0]]
checked = 0
for r in rows[1:]:
    q = float(r[0])
    p = construct(steps, drawn, q)
    for name, (x, y) in p.items():
        if name + ".x" not in head:
            continue
        gx, gy = float(r[head.index(name + ".x")]), float(r[head.index(name + ".y")])
        if math.hypot(gx - x, gy - y) > 1e-9:
            print("%s: at q = %.9g, %s is at (%.9g, %.9g) m, the construction puts it at "
                  "(%.9g, %.9g)" % (sys.argv[1], q, name, gx, gy, x, y))
            sys.exit(1)
        checked += 1
if checked < 2 * (len(rows) - 1):
    print("%s: only %d positions checked" % (sys.argv[1], checked))
    sys.exit(1)
print("%s: %d rows, %d point positions as constructed" % (sys.argv[1], len(rows) - 1, checked))
