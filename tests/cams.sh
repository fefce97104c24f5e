#!/bin/sh
# tests/cams.sh: cam-follower pairs (docs/cams.md) against closed forms and
# the geometry they stand for, on the shipped examples
# mechanisms/cams/translating-roller.yaml (an offset roller follower:
# cycloidal rise, 3-4-5 return), cam-fourbar.yaml (a roller follower turned
# clockwise, driving a four-bar: 4-5-6-7 rise, cycloidal return) and
# flat-faced.yaml (a flat-faced follower, harmonic laws), their goldens
# (tests/golden/cams/), and tests/cams/arm.yaml (a cam and its follower on
# a swinging arm).
# The follower's motion against the laws written out here; the base
# position against the base circle (the roller's centre base + roller from
# the cam's centre); rates against differences of positions; the profile
# of mech cam against the envelope it must be (the roller touches it and
# never cuts it; a flat face is tangent to it), its curvature against
# three-point circles of its own points, its pressure angle against the
# normal of the pitch curve's differences; load-time errors with
# file:line:column; --jit bit for bit.
# Run from the repository root:  MECH=build/mech sh tests/cams.sh
NAME=cams . tests/lib.sh
D=mechanisms/cams

if run "check translating" 0 "$MECH" check "$D/translating-roller.yaml"; then
    has_line "$tmp/out" "^  mobility   1 = 3\*(3-1) - 2\*2 - 0 - 1 cam, drivers 1\$" "check: the cam in the mobility"
    has_line "$tmp/out" "^  cam        disc: cam 'cam' on 'ground' turning ccw, roller follower slider 'y_R' at 48.9898 mm + s, offset -10 mm" "check: the cam's line"
    has_line "$tmp/out" "^  cam design disc: pressure angle at most" "check: the design line"
fi

# the laws of the programs, in awk: s, s', s'' of a rise or return at u
LAWS='function cyc(u, k) { return k == 0 ? u - sin(2 * PI * u) / (2 * PI) : k == 1 ? 1 - cos(2 * PI * u) : 2 * PI * sin(2 * PI * u) }
function p345(u, k) { return k == 0 ? 10 * u^3 - 15 * u^4 + 6 * u^5 : k == 1 ? 30 * u^2 - 60 * u^3 + 30 * u^4 : 60 * u - 180 * u^2 + 120 * u^3 }
function p4567(u, k) { return k == 0 ? 35 * u^4 - 84 * u^5 + 70 * u^6 - 20 * u^7 : k == 1 ? 140 * u^3 - 420 * u^4 + 420 * u^5 - 140 * u^6 : 420 * u^2 - 1680 * u^3 + 2100 * u^4 - 840 * u^5 }
function harm(u, k) { return k == 0 ? (1 - cos(PI * u)) / 2 : k == 1 ? PI * sin(PI * u) / 2 : PI * PI * cos(PI * u) / 2 }'
# translating-roller.yaml's program: cycloidal rise of h over 120 deg, dwell
# 60, 3-4-5 return over 120, dwell 60 (x in rad, D = pi / 180)
ROLLER_LIFT='
function lift(x, k,   b, u) { b = 120 * D
    if (x < b) { u = x / b; return h * cyc(u, k) / b^k }
    if (x < 180 * D) return k == 0 ? h : 0
    if (x < 300 * D) { u = (x - 180 * D) / b; return k == 0 ? h - h * p345(u, 0) : -h * p345(u, k) / b^k }
    return 0 }'

# 1. translating roller, offset 10 mm: R = (10, sqrt(50^2 - 10^2) + s) mm,
# vy = s' w, ay = s'' w^2 (w = 60 rpm); rise 20 mm cycloidal over 120 deg,
# dwell 60, return 3-4-5 over 120, dwell 60
check_translating() {  # FILE: mech solve's columns of translating-roller.yaml
    awk -F, "$LAWS$ROLLER_LIFT"'
        BEGIN { PI = atan2(0, -1); D = PI / 180; h = 0.020; w = 2 * PI; worst = 0; d0 = sqrt(0.05^2 - 0.01^2) }
        NR > 1 { x = $1; if (x >= 2 * PI - 1e-12) x = 0
            e[1] = ($2 - 0.010) / h; e[2] = ($3 - d0 - lift(x, 0)) / h
            e[3] = ($5 - lift(x, 1) * w) / (h * w); e[4] = ($7 - lift(x, 2) * w * w) / (h * w * w)
            for (k = 1; k <= 4; k++) { a = e[k] < 0 ? -e[k] : e[k]; if (a > worst) worst = a } }
        END { printf "%.3g\n", worst; exit !(worst < 1e-12) }' "$1" >"$tmp/w" &&
        pass || fail "translating against the closed form ($1): worst relative error $(cat "$tmp/w")"
}
if run "solve translating" 0 "$MECH" solve "$D/translating-roller.yaml" -o "$tmp/t.csv"; then
    check_translating "$tmp/t.csv"
fi
check_translating tests/golden/cams/translating-roller.csv  # the reviewed golden itself

# 2. oscillating roller (cw cam) driving a four-bar: the follower's angle
# less its base angle is the lift at x = -q (4-5-6-7 rise of 15 deg over
# 150, dwell 30, cycloidal return over 150, dwell 30); at zero lift the
# roller's centre R is base + roller = 40 mm from the cam's centre O (the
# base position, found by the loader), and it moves away as the lift grows
if run "solve oscillating" 0 "$MECH" solve "$D/cam-fourbar.yaml" --outputs R,follower,rocker -o "$tmp/o.csv"; then
    awk -F, "$LAWS"'
        function lift(x, k,   b, u) { b = 150 * D
            if (x < b) { u = x / b; return h * p4567(u, k) / b^k }
            if (x < 180 * D) return k == 0 ? h : 0
            if (x < 330 * D) { u = (x - 180 * D) / b; return k == 0 ? h - h * cyc(u, 0) : -h * cyc(u, k) / b^k }
            return 0 }
        BEGIN { PI = atan2(0, -1); D = PI / 180; h = 15 * D; worst = 0; base = 0 }
        NR == 2 { base = $8 }
        NR > 1 { x = -$1; if (x >= 2 * PI - 1e-12) x = 0
            e = ($8 - base - lift(x, 0)) / h; if (e < 0) e = -e; if (e > worst) worst = e
            r = sqrt($2^2 + $3^2)
            if (lift(x, 0) == 0) { e = (r - 0.040) / 0.040; if (e < 0) e = -e; if (e > worst) worst = e }
            if (lift(x, 0) > 0 && r <= 0.040) worst = 1 }
        END { printf "%.3g\n", worst; exit !(worst < 1e-12) }' "$tmp/o.csv" >"$tmp/w" &&
        pass || fail "oscillating against the closed form and the base circle: worst $(cat "$tmp/w")"
    # the rocker's rate against central differences of its angle over a
    # finer sweep (the four-bar driven through the cam): 0.5 deg, O(h^2)
    "$MECH" solve "$D/cam-fourbar.yaml" --outputs rocker,cam --steps 720 -o "$tmp/r.csv" 2>/dev/null
    awk -F, 'NR > 1 { q[NR] = $1; a[NR] = $2; om[NR] = $3; w[NR] = $6; n = NR }
        END { worst = 0; big = 0
            for (i = 3; i < n; i++) { d = (a[i + 1] - a[i - 1]) / (q[i + 1] - q[i - 1]) * w[i]
                e = d - om[i]; if (e < 0) e = -e; if (e > worst) worst = e; if (om[i] > big) big = om[i]; if (-om[i] > big) big = -om[i] }
            printf "%.3g\n", worst / big; exit !(big > 0 && worst / big < 1e-3) }' "$tmp/r.csv" >"$tmp/w" &&
        pass || fail "oscillating: the rocker's omega against differences: $(cat "$tmp/w")"
fi

# 2b. a cam and its follower on a swinging arm (tests/cams/arm.yaml: the
# arm 30 deg sin(2 pi t / 1 s), the cam 360 deg/s t, both laws of time):
# the lift is the program's at the cam's angle on the arm, its rate s'
# times the difference of their rates, its acceleration the chain rule's
if run "solve arm" 0 "$MECH" solve tests/cams/arm.yaml -o "$tmp/a.csv"; then
    awk -F, "$LAWS$ROLLER_LIFT"'
        BEGIN { PI = atan2(0, -1); D = PI / 180; h = 0.020; worst = 0; d0 = sqrt(0.05^2 - 0.01^2) }
        NR > 1 { x = $11 - $8; w = $12 - $9; al = $13 - $10; x -= 2 * PI * int(x / (2 * PI)); if (x < 0) x += 2 * PI
            e[1] = ($14 - d0 - lift(x, 0)) / h; e[2] = ($15 - lift(x, 1) * w) / (h * 2 * PI)
            e[3] = ($16 - lift(x, 2) * w * w - lift(x, 1) * al) / (h * 40 * PI * PI)
            for (k = 1; k <= 3; k++) { a = e[k] < 0 ? -e[k] : e[k]; if (a > worst) worst = a } }
        END { printf "%.3g\n", worst; exit !(worst < 1e-12) }' "$tmp/a.csv" >"$tmp/w" &&
        pass || fail "arm: the lift against the program at the cam's angle on the arm: $(cat "$tmp/w")"
fi

# 3. the profile of mech cam: the roller's circle about each pitch point
# touches the profile (its own contact point is rr away) and no profile
# point is nearer (no cut); the pitch curve's radius against the circle
# through three neighbouring points (0.1 deg apart); the pressure angle
# against the normal of the pitch curve's central differences and the
# follower's line turned into the cam's frame
if run "cam translating" 0 "$MECH" cam "$D/translating-roller.yaml" --step 0.1 -o "$tmp/p.csv" \
    --svg "$tmp/p.svg" --dxf "$tmp/p.dxf"; then
    has_line "$tmp/out" "^points       3600 over a turn, 0.1 deg apart\$" "cam: the points"
    python3 - "$tmp/p.csv" <<'EOF' && pass || fail "cam translating: the profile's geometry"
import csv, math, sys
rows = [[float(v) for v in r] for r in list(csv.reader(open(sys.argv[1])))[1:]]
rr, n, bad = 0.010, len(rows), []
worst = max(abs(math.hypot(r[4] - r[6], r[5] - r[7]) - rr) for r in rows)
if worst > 1e-15: bad.append(f"contact {worst:.3g} m off the roller's circle")
# the contact is on the cam's side of the roller (the centre O at the origin)
outer = sum((r[4] - r[6]) * r[4] + (r[5] - r[7]) * r[5] <= 0 for r in rows)
if outer: bad.append(f"{outer} contacts on the far side of the roller from the cam")
cut = 0.0
for r in rows[::7]:  # every pitch point against every profile point
    d = min(math.hypot(r[4] - q[6], r[5] - q[7]) for q in rows)
    cut = max(cut, rr - d)
if cut > 1e-9: bad.append(f"the roller cuts the profile by {cut:.3g} m")
rho = press = 0.0
edges = (0, 120, 180, 300)  # the segments' ends: the jerk jumps, the three-point circle across one is O(h)
for k in range(1, n - 1):
    if min(abs(math.degrees(rows[k][0]) - e) for e in edges) < 1e-6:
        continue
    (x0, y0), (x1, y1), (x2, y2) = [(rows[j][4], rows[j][5]) for j in (k - 1, k, k + 1)]
    a, b, c = math.hypot(x1 - x0, y1 - y0), math.hypot(x2 - x1, y2 - y1), math.hypot(x2 - x0, y2 - y0)
    area = abs((x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)) / 2
    if area > 0:
        rho = max(rho, abs(a * b * c / (4 * area) - rows[k][9]) / abs(rows[k][9]))
    # the normal of the pitch curve, outwards, and the follower's direction
    # (the line at 90 deg on the ground) seen from the cam turned by x
    tx, ty = x2 - x0, y2 - y0
    nx, ny = -ty, tx  # the curve runs clockwise (the cam turns ccw): outward is left
    th = rows[k][0]
    ux, uy = math.cos(math.pi / 2 - th), math.sin(math.pi / 2 - th)
    phi = math.atan2(ux * ny - uy * nx, ux * nx + uy * ny)
    press = max(press, abs(phi - rows[k][8]))
if rho > 1e-5: bad.append(f"radius of curvature {rho:.3g} from three-point circles")
if press > 1e-5: bad.append(f"pressure angle {press:.3g} rad from the pitch curve's normal")
for b in bad: print("FAIL:", b)
sys.exit(1 if bad else 0)
EOF
    # the pitch curve is where mech solve puts the roller's centre: R(q)
    # turned back by the cam's angle q (the cam's centre at the origin)
    awk -F, 'FNR == 1 { f++ } f == 1 && FNR > 1 { px[FNR] = $5; py[FNR] = $6 }
        f == 2 && FNR > 1 && $1 < 6.28 { k = int($1 * 1800 / atan2(0, -1) + 0.5) + 2
            c = cos($1); s = sin($1); x = c * $2 + s * $3; y = -s * $2 + c * $3
            e = (x - px[k]) ^ 2 + (y - py[k]) ^ 2; if (e > worst) worst = e }
        END { printf "%.3g\n", sqrt(worst); exit !(sqrt(worst) < 1e-15) }' "$tmp/p.csv" "$tmp/t.csv" >"$tmp/w" &&
        pass || fail "cam translating: the pitch curve is not the solved roller's path: $(cat "$tmp/w") m"
    python3 -c "import sys, xml.dom.minidom as X; d = X.parse(sys.argv[1]); sys.exit(len(d.getElementsByTagName('polygon')) != 2)" "$tmp/p.svg" &&
        pass || fail "cam: the SVG outline is not well-formed or lacks its two curves"
    [ "$(grep -c '^POLYLINE$' "$tmp/p.dxf")" -eq 2 ] && [ "$(grep -c '^VERTEX$' "$tmp/p.dxf")" -eq 7200 ] &&
        [ "$(tail -n 1 "$tmp/p.dxf")" = EOF ] && pass || fail "cam: the DXF outline"
fi

# 4. flat-faced: the contact point lies on the face (base + s along the
# follower's line from the centre, turned into the cam's frame) and the
# profile's own tangent there is the face's direction; its radius of
# curvature base + s + s'' against the harmonic laws written out
if run "cam flat" 0 "$MECH" cam "$D/flat-faced.yaml" --step 0.1 -o "$tmp/f.csv"; then
    has_line "$tmp/out" "^design       cam_y_F: face from -16.8 to 4.8 mm of the follower's line (width at least 21.6 mm)" "cam flat: the face"
    python3 - "$tmp/f.csv" <<'EOF' && pass || fail "cam flat: the profile's geometry"
import csv, math, sys
rows = [[float(v) for v in r] for r in list(csv.reader(open(sys.argv[1])))[1:]]
n, bad, on, tang, rho = len(rows), [], 0.0, 0.0, 0.0
h, b, rb = 0.018, 150 * math.pi / 180, 0.035
for k in range(n):
    x, px, py = rows[k][0], rows[k][6], rows[k][7]
    th = x + math.radians(30)  # start 30 deg
    ux, uy = math.cos(math.pi / 2 - th), math.sin(math.pi / 2 - th)
    if x < b: u = x / b; s, dds = h * (1 - math.cos(math.pi * u)) / 2, h * math.pi ** 2 * math.cos(math.pi * u) / (2 * b * b)
    elif x < math.radians(180): s, dds = h, 0.0
    elif x < math.radians(330): u = (x - math.radians(180)) / b; s, dds = h - h * (1 - math.cos(math.pi * u)) / 2, -h * math.pi ** 2 * math.cos(math.pi * u) / (2 * b * b)
    else: s, dds = 0.0, 0.0
    on = max(on, abs(px * ux + py * uy - (rb + s)))
    rho = max(rho, abs(rows[k][10] - (rb + s + dds)))
    if 0 < k < n - 1 and min(abs(math.degrees(x) - e) for e in (0, 150, 180, 330)) > 1e-6:
        tx, ty = rows[k + 1][6] - rows[k - 1][6], rows[k + 1][7] - rows[k - 1][7]
        tang = max(tang, abs(tx * ux + ty * uy) / math.hypot(tx, ty))
if on > 1e-15: bad.append(f"contact {on:.3g} m off the face")
if tang > 1e-6: bad.append(f"the profile's tangent {tang:.3g} off the face's direction")
if rho > 1e-12: bad.append(f"radius of curvature {rho:.3g} m off base + s + s''")
for b in bad: print("FAIL:", b)
sys.exit(1 if bad else 0)
EOF
fi

# 4a. an oscillating flat face (oscillating-flat.yaml): the face's line
# through the solved A and B is never nearer the cam's centre than the base
# radius, and exactly there at zero lift; the follower's angle is its base
# angle less the lift (the lift turns it clockwise here, away from the
# cam: 12 deg cycloidal over 150, dwell 30, back over 150, dwell 30); the
# profile's point at each cam angle, turned by that angle, lies on the
# solved face; its radius against three-point circles (0.1 deg)
if run "solve oscillating flat" 0 "$MECH" solve "$D/oscillating-flat.yaml" -o "$tmp/of.csv" &&
   run "cam oscillating flat" 0 "$MECH" cam "$D/oscillating-flat.yaml" --step 5 -o "$tmp/of5.csv" &&
   has_line "$tmp/out" "^design       disc: face from 27.7134 to 61.1888 mm along it from its first point (width at least 33.4755 mm)" "cam oscillating flat: the face's extent" &&
   run "cam oscillating flat, fine" 0 "$MECH" cam "$D/oscillating-flat.yaml" --step 0.1 -o "$tmp/of01.csv"; then
    python3 - "$tmp/of.csv" "$tmp/of5.csv" "$tmp/of01.csv" <<'EOF' && pass || fail "oscillating flat: the geometry"
import csv, math, sys
rd = lambda f: [[float(v) for v in r] for r in list(csv.reader(open(f)))[1:]]
S, P, R = rd(sys.argv[1]), rd(sys.argv[2]), rd(sys.argv[3])
h, b, bad = math.radians(12), math.radians(150), []
def lift(x):
    if x < b: u = x / b; return h * (u - math.sin(2 * math.pi * u) / (2 * math.pi))
    if x < math.radians(180): return h
    if x < math.radians(330): u = (x - math.radians(180)) / b; return h - h * (u - math.sin(2 * math.pi * u) / (2 * math.pi))
    return 0.0
base, on, dist, ang = S[0][13], 0.0, 0.0, 0.0
for i, r in enumerate(S[:-1]):
    q, ax, ay, bx, by = r[0], r[1], r[2], r[7], r[8]
    dx, dy = bx - ax, by - ay; L = math.hypot(dx, dy)
    d = abs(ax * dy - ay * dx) / L
    if d < 0.04 - 1e-15: dist = max(dist, 0.04 - d)
    if lift(q) == 0.0: dist = max(dist, abs(d - 0.04))
    ang = max(ang, abs(r[13] - (base - lift(q))))
    c, s = math.cos(q), math.sin(q); px, py = P[i][6], P[i][7]
    on = max(on, abs((c * px - s * py - ax) * dy - (s * px + c * py - ay) * dx) / L)
if dist > 1e-15: bad.append(f"the face {dist:.3g} m off the base circle")
if ang > 1e-12: bad.append(f"the follower's angle {ang:.3g} rad off the laws")
if on > 1e-15: bad.append(f"the profile {on:.3g} m off the solved face")
rho = 0.0
for k in range(1, len(R) - 1):
    if min(abs(math.degrees(R[k][0]) - e) for e in (0, 150, 180, 330)) < 1e-6: continue
    (x0, y0), (x1, y1), (x2, y2) = [(R[j][6], R[j][7]) for j in (k - 1, k, k + 1)]
    a1, b1, c1 = math.hypot(x1 - x0, y1 - y0), math.hypot(x2 - x1, y2 - y1), math.hypot(x2 - x0, y2 - y0)
    area = abs((x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)) / 2
    if area > 0: rho = max(rho, abs(a1 * b1 * c1 / (4 * area) - R[k][10]) / abs(R[k][10]))
if rho > 1e-5: bad.append(f"radius of curvature {rho:.3g} from three-point circles")
for m in bad: print("FAIL:", m)
sys.exit(1 if bad else 0)
EOF
fi

# 4b. the shipped examples against their reviewed goldens (make golden):
# the motion (checked above against the closed forms) and the profile
for f in "$D"/*.yaml; do
    n=$(basename "$f" .yaml)
    if run "golden $n" 0 "$MECH" solve "$f" -o "$tmp/g.csv"; then
        run "golden $n: compare" 0 "$MECH" compare "$tmp/g.csv" "tests/golden/cams/$n.csv" --rtol 1e-12 --atol 1e-15 && pass
    fi
    if run "golden $n profile" 0 "$MECH" cam "$f" -o "$tmp/gp.csv"; then
        run "golden $n: compare the profile" 0 "$MECH" compare "$tmp/gp.csv" "tests/golden/cams/$n.profile.csv" --rtol 1e-12 --atol 1e-15 && pass
    fi
done

# 4c. forces (tests/cams/forces.yaml: the follower's weight holds it on the
# cam, 60 rpm): along the follower's line F cos(phi) - m g = m y'' (phi the
# pressure angle of mech cam at the same cam angle, y'' from the laws), the
# cam's torque T w = m (g + y'') y' (the only power), every row's power
# balance to 1e-12; at 400 rpm the follower lifts off where y'' < -g
F=tests/cams/forces.yaml
if run "forces" 0 "$MECH" solve "$F" -o "$tmp/fo.csv" && run "forces: profile" 0 "$MECH" cam "$F" --step 5 -o "$tmp/fp.csv"; then
    awk -F, 'FNR == 1 { f++ } f == 1 && FNR > 1 { phi[FNR] = $9 }
        f == 2 && FNR > 1 { k = FNR; if (k > 73) k = 2
            m = 0.5; g = 9.81; w = 2 * atan2(0, -1); load = m * (g + $7)
            e1 = ($20 * cos(phi[k]) - load) / (m * g); if (e1 < 0) e1 = -e1; if (e1 > worst) worst = e1
            e2 = ($18 * w - load * $5) / (m * g * 0.12); if (e2 < 0) e2 = -e2; if (e2 > worst) worst = e2
            r = $19 < 0 ? -$19 : $19; if (r > res) res = r }
        END { printf "%.3g %.3g\n", worst, res; exit !(worst < 1e-12 && res < 1e-12) }' "$tmp/fp.csv" "$tmp/fo.csv" >"$tmp/w" &&
        pass || fail "forces: the contact force, the torque or the power balance: $(cat "$tmp/w")"
fi
# the oscillating follower driving a four-bar with masses, gravity and a
# torsion spring, and the flat face pressed by a spring: a frictionless
# contact does no work, so every row's power balance closes (a wrong
# contact normal would put the contact force's power in it)
for f in forces-fourbar forces-flat forces-oscflat; do
    if run "forces $f" 0 "$MECH" solve "tests/cams/$f.yaml" -o "$tmp/$f.csv"; then
        awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i ~ /^power.residual/) c = i }
            NR > 1 { r = $c < 0 ? -$c : $c; if (r > w) w = r }
            END { printf "%.3g\n", w; exit !(c > 0 && w < 1e-12) }' "$tmp/$f.csv" >"$tmp/w" &&
            pass || fail "forces $f: the power balance $(cat "$tmp/w")"
        grep -q "lifts off" "$tmp/err" && fail "forces $f: a lift-off: $(cat "$tmp/err")" || pass
    fi
done
# forward dynamics: a free cam lifting its follower against gravity
# (tests/cams/free.yaml) slows down; the energy balance (kinetic + potential
# against the work) closes to 1e-8 of the kinetic energy at rtol 1e-10
if run "simulate a free cam" 0 "$MECH" simulate tests/cams/free.yaml --rtol 1e-10 --atol 1e-12 -o "$tmp/fr.csv"; then
    awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) { if ($i ~ /^energy.balance/) b = i; if ($i ~ /^energy.kinetic/) k = i; if ($i ~ /^cam.omega/) o = i } }
        NR > 1 { x = $b < 0 ? -$b : $b; if (x > w) w = x; if ($k > m) m = $k; last = $o }
        END { printf "%.3g %.3g\n", w / m, last; exit !(b && k && w / m < 1e-8 && last < 6.28 && last > 0) }' "$tmp/fr.csv" >"$tmp/w" &&
        pass || fail "simulate a free cam: the energy balance or the slowing: $(cat "$tmp/w")"
fi
sed 's/^  speed: 60 rpm/  speed: 400 rpm/' "$F" >"$tmp/fast.yaml"
run "lift-off" 0 "$MECH" solve "$tmp/fast.yaml" -o "$tmp/x.csv" &&
    has_line "$tmp/err" "fast.yaml:31:5: warning: cam 'disc': the follower lifts off at driver angle = 65 deg: the contact would have to pull" "lift-off: the warning"
run "forces: jit falls back" 0 "$MECH" solve "$F" --jit -o "$tmp/foj.csv" &&
    has_line "$tmp/err" "forces through a cam pair ('disc') are not generated" "forces: jit's note" &&
    { cmp -s "$tmp/fo.csv" "$tmp/foj.csv" && pass || fail "forces: the fallback's rows differ"; }

# 4e. friction at the contact (tests/cams/friction.yaml: a flat face on a
# line through the centre, mu 0.1, held by its weight, 60 rpm): the face
# carries F = m (g + y''), and the cam's moment balance about its centre,
# the normal force at the contact's offset s' along the face and the
# friction mu F at the lever base + s, gives T = m (g + y'') (s' + mu
# (base + s)); the power balance still closes (with the friction's power)
if run "friction" 0 "$MECH" solve tests/cams/friction.yaml -o "$tmp/fri.csv"; then
    awk -F, "$LAWS"'
        function lift(x, k,   b, u) { b = 150 * D
            if (x < b) { u = x / b; return h * cyc(u, k) / b^k }
            if (x < 180 * D) return k == 0 ? h : 0
            if (x < 330 * D) { u = (x - 180 * D) / b; return k == 0 ? h - h * cyc(u, 0) : -h * cyc(u, k) / b^k }
            return 0 }
        BEGIN { PI = atan2(0, -1); D = PI / 180; h = 0.018; w = 2 * PI; m = 0.5; g = 9.81; mu = 0.1 }
        NR > 1 { x = $1; if (x >= 2 * PI - 1e-12) x = 0
            load = m * (g + lift(x, 2) * w * w)
            e1 = ($19 - load) / (m * g); e2 = ($15 - load * (lift(x, 1) + mu * (0.035 + lift(x, 0)))) / (m * g * 0.05)
            r = $16; for (k = 1; k <= 3; k++) { v = k == 1 ? e1 : k == 2 ? e2 : r; if (v < 0) v = -v; if (v > worst) worst = v } }
        END { printf "%.3g\n", worst; exit !(worst < 1e-12) }' "$tmp/fri.csv" >"$tmp/w" &&
        pass || fail "friction: the force, the moment balance or the power balance: $(cat "$tmp/w")"
fi
sed 's/^    contact: flat-faced/    contact: knife-edge/' tests/cams/friction.yaml >"$tmp/knife.yaml"
run "friction on a knife" 0 "$MECH" solve "$tmp/knife.yaml" -o "$tmp/x.csv"
sed 's/^    base_radius: 35 mm/    base_radius: 35 mm\n    roller_radius: 5 mm/; s/^    contact: flat-faced/    contact: roller/' tests/cams/friction.yaml >"$tmp/roll.yaml"
sed 's/^    contact: roller/    contact: knife-edge\n    friction: 0.1/; /roller_radius/d' tests/cams/free.yaml >"$tmp/free-fric.yaml"
run "simulate refuses contact friction" 2 "$MECH" simulate "$tmp/free-fric.yaml" -o "$tmp/x.csv" &&
    has_line "$tmp/err" "error: cam 'disc' has Coulomb friction at its contact, which mech simulate does not model" "simulate refuses contact friction: message"
run "friction on a roller" 2 "$MECH" check "$tmp/roll.yaml" &&
    has_line "$tmp/err" "roll.yaml:[0-9]*:15: error: a roller rolls on the cam: there is no sliding friction at its contact" "friction on a roller: message"

# 4f. the design quantities as columns of mech solve (--outputs NAME or
# outputs: {cams: [NAME]}): at each row the cam's angle on its arm and the
# quantities mech cam gives at that angle
if run "design columns" 0 "$MECH" solve "$D/translating-roller.yaml" --outputs R,disc -o "$tmp/dq.csv" &&
   run "design columns: the table" 0 "$MECH" cam "$D/translating-roller.yaml" --step 5 -o "$tmp/dq5.csv"; then
    has_line "$tmp/dq.csv" "^q \[rad\],R.x \[m\],.*,disc.x \[rad\],disc.pressure_angle \[rad\],disc.rho_pitch \[m\],disc.rho_profile \[m\]\$" "design columns: the header"
    awk -F, 'FNR == 1 { f++ } f == 1 && FNR > 1 { x[FNR] = $1; p[FNR] = $9; rp[FNR] = $10; rf[FNR] = $11 }
        f == 2 && FNR > 1 { k = FNR; if (k > 73) k = 2
            e = ($8 - $1); if (e < 0) e = -e; if (e > w) w = e
            e = ($9 - p[k]); if (e < 0) e = -e; if (e > w) w = e
            e = ($10 - rp[k]) / rp[k]; if (e < 0) e = -e; if (e > w) w = e
            e = ($11 - rf[k]) / rf[k]; if (e < 0) e = -e; if (e > w) w = e }
        END { printf "%.3g\n", w; exit !(w < 1e-12) }' "$tmp/dq5.csv" "$tmp/dq.csv" >"$tmp/w" &&
        pass || fail "design columns against mech cam's table: $(cat "$tmp/w")"
fi
sed 's/^  sliders: \[y_R\]/  sliders: [y_R]\n  cams: [disc]/' "$D/translating-roller.yaml" >"$tmp/dcol.yaml"
run "design columns: jit refuses" 0 "$MECH" solve "$tmp/dcol.yaml" --jit -o "$tmp/x.csv" &&
    has_line "$tmp/err" "the design quantities of cam 'disc' are not generated" "design columns: jit's note"
sed 's/^  sliders: \[y_R\]/  sliders: [y_R]\n  cams: [nope]/' "$D/translating-roller.yaml" >"$tmp/dbad.yaml"
run "design columns: no such cam" 2 "$MECH" check "$tmp/dbad.yaml" &&
    has_line "$tmp/err" "dbad.yaml:[0-9]*:10: error: 'nope' is not a cam of the file's 'cams:'" "design columns: no such cam: message"

# 4d. mech plot and mech report draw each cam's lift, its three derivatives
# against the cam's angle and its profile with the pitch curve
if run "plot a cam" 0 "$MECH" plot "$D/translating-roller.yaml" --out "$tmp/figs"; then
    for k in lift velocity acceleration jerk profile; do
        has_line "$tmp/out" "^$tmp/figs/translating-roller-cam-disc-$k.svg\$" "plot a cam: $k said"
        python3 -c "import sys, xml.dom.minidom as X; X.parse(sys.argv[1])" "$tmp/figs/translating-roller-cam-disc-$k.svg" &&
            pass || fail "plot a cam: $k is not well-formed"
    done
    has_line "$tmp/figs/translating-roller-cam-disc-lift.svg" "cam angle x of 'disc' \[deg\]" "plot a cam: the x axis"
fi
if run "report a cam" 0 "$MECH" report "$D/cam-fourbar.yaml" -o "$tmp/cam.html"; then
    [ "$(grep -c "<title[^>]*>Cam 'disc'" "$tmp/cam.html")" -eq 5 ] && pass || fail "report a cam: not its 5 figures"
    grep -q 'class="cam"' "$tmp/cam.html" && pass || fail "report a cam: the animation lacks the cam"
fi

# 4g. the drawn form (mech convert) of a file with a cam solves the same
if run "convert a cam" 0 "$MECH" convert "$D/translating-roller.yaml" -o "$tmp/drawn.yaml" &&
   run "convert a cam: solve" 0 "$MECH" solve "$tmp/drawn.yaml" -o "$tmp/drawn.csv"; then
    has_line "$tmp/drawn.yaml" "^drawing:" "convert a cam: the drawn form"
    run "convert a cam: compare" 0 "$MECH" compare "$tmp/drawn.csv" tests/golden/cams/translating-roller.csv --rtol 1e-12 --atol 1e-15 && pass
fi

# 5. the generated code: bit for bit
if run "jit translating" 0 "$MECH" solve "$D/translating-roller.yaml" --jit -o "$tmp/tj.csv"; then
    cmp -s "$tmp/t.csv" "$tmp/tj.csv" && pass || fail "jit translating: not bit for bit"
fi
run "jit oscillating" 0 "$MECH" solve "$D/cam-fourbar.yaml" --outputs R,follower,rocker --jit -o "$tmp/oj.csv" &&
    { cmp -s "$tmp/o.csv" "$tmp/oj.csv" && pass || fail "jit oscillating: not bit for bit"; }

# 6. what is refused, where
bad() {  # bad LABEL STATUS PATTERN SED-SCRIPT [FILE]: the file edited, then mech check
    sed "$4" "$D/${5:-translating-roller.yaml}" >"$tmp/bad.yaml"
    run "$1" "$2" "$MECH" check "$tmp/bad.yaml" && has_line "$tmp/err" "$3" "$1: message"
}
bad "offset too large" 2 "bad.yaml:28:15: error: the follower's line (slider 'y_R') passes 60 mm from the cam's centre O, not inside the base circle plus the roller (50 mm)" 's/^  T: \[10, 0\]/  T: [60, 0]/'
bad "undercut" 2 "bad.yaml:26:5: error: cam 'disc': the profile is undercut at [0-9.]* deg of the cam: the pitch curve's radius of curvature there, [0-9.]* mm, is below the roller's 20 mm" 's/^    roller_radius: 10 mm/    roller_radius: 20 mm/; s/^    base_radius: 40 mm/    base_radius: 5 mm/; s/^  T: \[10, 0\]/  T: [0, 0]/; s/over: 120 deg, law: cycloidal/over: 60 deg, law: cycloidal/; 0,/dwell: 60 deg/ s//dwell: 120 deg/'
bad "flat undercut" 2 "bad.yaml:26:5: error: cam 'cam_y_F': the profile is undercut at [0-9.]* deg of the cam: its radius of curvature base + s + s'' there is -[0-9.]* mm" 's/^    base_radius: 35 mm/    base_radius: 3 mm/; s/rise: 18 mm, over: 150 deg/rise: 18 mm, over: 60 deg/; 0,/dwell: 30 deg/ s//dwell: 120 deg/' flat-faced.yaml
bad "unknown contact" 2 "bad.yaml:29:14: error: 'contact' is roller, knife-edge or flat-faced, not 'ball'" 's/^    contact: roller/    contact: ball/'
bad "at on a slider" 2 "bad.yaml:[0-9]*:5: error: a translating follower touches the cam at its slider's point: 'at' does not apply" 's/^    follower: y_R/    follower: y_R\n    at: R/'
bad "program of" 2 "bad.yaml:[0-9]*:7: error: a cam's program has no 'of': its variable is the cam's angle" 's/^    program:/    program:\n      of: t/'
bad "oscillating flat without face" 2 "error: an oscillating flat-faced follower needs 'face: \[A, B\]'" 's/^    contact: roller/    contact: flat-faced/; /roller_radius/d; /^    at: R/d' cam-fourbar.yaml
bad "out of reach" 2 "bad.yaml:[0-9]*:5: error: cam 'disc': the follower's point R (80 mm from its pivot, which is 100 mm from the cam's centre) cannot reach the base circle plus the roller (10.5 mm)" 's/^    base_radius: 30 mm/    base_radius: 0.5 mm/' cam-fourbar.yaml
bad "open profile" 2 "error: cam 'disc': the program rises 10 mm more than it returns over its period" 's/return: 20 mm, over: 120 deg/return: 10 mm, over: 120 deg/'
bad "period not a turn" 2 "error: cam 'disc': the program's period 350 deg does not divide a turn" '0,/dwell: 60 deg/ s//dwell: 50 deg/'
sed 's/over: 120 deg, law: cycloidal/over: 60 deg, law: cycloidal/; s/over: 120 deg, law: 3-4-5/over: 60 deg, law: 3-4-5/; s/dwell: 60 deg/dwell: 30 deg/' "$D/translating-roller.yaml" >"$tmp/twice.yaml"
if run "twice a turn" 0 "$MECH" cam "$tmp/twice.yaml" --step 1 -o "$tmp/twice.csv"; then
    awk -F, 'NR > 1 { s[NR - 2] = $2; n = NR - 1 }
        END { for (i = 0; i < 180; i++) { e = s[i] - s[i + 180]; if (e < 0) e = -e; if (e > w) w = e }
              exit !(n == 360 && w < 1e-15) }' "$tmp/twice.csv" &&
        pass || fail "twice a turn: the table is not a whole turn of the repeated program"
fi
bad "jump in the program" 2 "error: cam 'disc': an acceleration jump of [-0-9.]* mm/deg^2 (d2s/dx2) at 180 deg" 's/law: 3-4-5/law: harmonic/'
printf 'parameters:\n  rb: 40 mm\n' >"$tmp/par.yaml"
sed 's/^    base_radius: 40 mm/    base_radius: rb/' "$D/translating-roller.yaml" >>"$tmp/par.yaml"
run "sensitivity refused" 2 "$MECH" solve "$tmp/par.yaml" --sensitivity rb -o "$tmp/x.csv" &&
    has_line "$tmp/err" "error: parameter 'rb': sensitivities of a mechanism with a cam pair ('disc') are not computed yet" "sensitivity refused: message"
run "cam: output over the input" 2 "$MECH" cam "$D/translating-roller.yaml" -o "$D/translating-roller.yaml"
run "cam: no such cam" 2 "$MECH" cam "$D/translating-roller.yaml" --cam nope &&
    has_line "$tmp/err" "no cam 'nope' in the file" "no such cam: message"
run "cam: no cams" 2 "$MECH" cam mechanisms/fourbar.yaml &&
    has_line "$tmp/err" "the file has no 'cams:'" "no cams: message"

summary
