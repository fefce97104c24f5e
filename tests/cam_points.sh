#!/bin/sh
# tests/cam_points.sh: cams given by their profile's points (docs/cams.md 7).
# Truths:
# 1. an eccentric circular disc (radius 40 mm, its centre C 10 mm from the
#    cam's pivot) given as 360 points: whatever the follower, its contact
#    element keeps its distance from C (a roller's centre or a knife's tip
#    40 + roller from C; a flat face 40 from C), so with C turning at the
#    cam's speed, the distance, its rate and its acceleration written out
#    (d/dt |T - C|^2 = 0 twice) hold on mech solve's positions, velocities
#    and accelerations: translating knife-edge, roller and flat face,
#    oscillating knife-edge, roller and flat face;
# 2. the profile mech cam writes for a program's cam (0.1 deg), read back
#    as points, gives the program's motion (its golden) to the spline's
#    accuracy: the translating roller, the oscillating flat face and the
#    cam driving a four-bar;
# 3. --jit bit for bit; load-time errors with file:line:column.
# Run from the repository root:  MECH=build/mech sh tests/cam_points.sh
NAME=cam_points . tests/lib.sh
D=mechanisms/cams

# the disc's 360 points, inline (mm)
POINTS=$(awk 'BEGIN { PI = atan2(0, -1); printf "["
    for (i = 0; i < 360; i++) { t = 2 * PI * i / 360; printf "%s[%.17g, %.17g]", i ? ", " : "", 10 + 40 * cos(t), 40 * sin(t) }
    printf "]" }')

# disc FOLLOWER-LINES CAM-LINES OUTPUTS: a file with the disc on cam 'cam'
# turning about O at 60 rpm
disc() {
    cat <<EOF
name: Eccentric disc given by points
units: {length: mm, angle: deg}
ground:
  O: [0, 0]
  T: [5, 0]
  P: [0, 100]
  F: [100, 60]
links:
  cam:
    points:
      O: [0, 0]
$1
cams:
  - name: disc
    cam: cam
$2
    profile: $POINTS
driver:
  link: cam
  angle: {from: 0, to: 360, steps: 72}
  speed: 60 rpm
outputs:
  points: [$3]
EOF
}
TRANSLATING='  follower:
    points:
      R: [0, 0]
joints:
  - slider: R
    link: follower
    on: ground
    through: T
    angle: 90 deg
    name: y_R'
OSCILLATING='  follower:
    points:
      P: [0, 0]
      R: [-30, -55]'
OSC_FLAT='  follower:
    points:
      F: [0, 0]
      A: [-140, -15]
      B: [-20, -15]'
KNIFE='  follower:
    points:
      P: [0, 0]
      R: [-40, -80]'

# contact KIND RR FILE [P V A]: the roller's centre (knife's tip) R keeps RR + 40 mm
# from C = 10 mm (cos q, sin q): |R - C|, its rate (R - C).(R' - C') and its
# acceleration |R' - C'|^2 + (R - C).(R'' - C''), each over its scale
contact() {
    awk -F, -v rr="$2" 'BEGIN { PI = atan2(0, -1); w = 2 * PI; e = 0.010; r = 0.040 + rr; worst = 0 }
        NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
        { q = $col["q [rad]"]; cx = e * cos(q); cy = e * sin(q)
          vcx = -e * w * sin(q); vcy = e * w * cos(q); acx = -e * w * w * cos(q); acy = -e * w * w * sin(q)
          dx = $col["R.x [m]"] - cx; dy = $col["R.y [m]"] - cy
          vx = $col["R.vx [m/s]"] - vcx; vy = $col["R.vy [m/s]"] - vcy
          ax = $col["R.ax [m/s^2]"] - acx; ay = $col["R.ay [m/s^2]"] - acy
          if (rr < 0) {  # a flat face along x, its normal y
              k[1] = (dy - 0.040) / r; k[2] = vy / (e * w); k[3] = ay / (e * w * w)
          } else {
              k[1] = (sqrt(dx * dx + dy * dy) - r) / r; k[2] = (dx * vx + dy * vy) / (r * e * w)
              k[3] = (vx * vx + vy * vy + dx * ax + dy * ay) / (r * e * w * w) }
          for (i = 1; i <= 3; i++) { a = k[i] < 0 ? -k[i] : k[i]; if (a > m[i]) m[i] = a } }
        END { printf "%.2g %.2g %.2g\n", m[1], m[2], m[3]; exit !(NR > 30 && m[1] < tp && m[2] < tv && m[3] < ta) }' \
        tp="${4:-1e-9}" tv="${5:-1e-6}" ta="${6:-1e-3}" "$3" >"$tmp/w" &&
        { pass; [ -z "${VERBOSE:-}" ] || echo "$1: $(cat "$tmp/w")"; } || fail "$1: the contact's distance, rate, acceleration off by $(cat "$tmp/w") of their scales"
}

disc "$TRANSLATING" '    follower: y_R
    contact: knife-edge' R >"$tmp/tk.yaml"
run "translating knife" 0 "$MECH" solve "$tmp/tk.yaml" -o "$tmp/tk.csv" && contact "translating knife" 0 "$tmp/tk.csv"
disc "$TRANSLATING" '    follower: y_R
    contact: roller
    roller_radius: 8 mm' R >"$tmp/tr.yaml"
run "translating roller" 0 "$MECH" solve "$tmp/tr.yaml" -o "$tmp/tr.csv" && contact "translating roller" 0.008 "$tmp/tr.csv"
disc "$TRANSLATING" '    follower: y_R
    contact: flat-faced' R >"$tmp/tf.yaml"
run "translating flat" 0 "$MECH" solve "$tmp/tf.yaml" -o "$tmp/tf.csv" && contact "translating flat" -1 "$tmp/tf.csv"
disc "$KNIFE" '    follower: follower
    contact: knife-edge
    at: R' R >"$tmp/ok.yaml"
run "oscillating knife" 0 "$MECH" solve "$tmp/ok.yaml" -o "$tmp/ok.csv" && contact "oscillating knife" 0 "$tmp/ok.csv"
disc "$OSCILLATING" '    follower: follower
    contact: roller
    roller_radius: 8 mm
    at: R' R >"$tmp/or.yaml"
run "oscillating roller" 0 "$MECH" solve "$tmp/or.yaml" -o "$tmp/or.csv" && contact "oscillating roller" 0.008 "$tmp/or.csv"
if run "check oscillating roller" 0 "$MECH" check "$tmp/or.yaml"; then
    has_line "$tmp/out" "cam        disc: .* base radius 30 mm, roller 8 mm, profile of 360 points (the lift at every 0.1 deg)" "check: the profile's cam, its base circle 40 - 10 mm"
fi

# mech cam's profile of the disc given by points (the envelope of the
# roller over the derived lift, in the cam's frame) lies on the disc:
# 40 mm from its centre (10, 0) mm, every 0.1 deg
for f in tr tf ok; do
    if run "cam $f" 0 "$MECH" cam "$tmp/$f.yaml" --step 0.1 -o "$tmp/$f.p.csv"; then
        awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
            { x = $col["profile.x [m]"] - 0.010; y = $col["profile.y [m]"]; e = sqrt(x * x + y * y) - 0.040
              if (e < 0) e = -e; if (e > w) w = e }
            END { printf "%.2g m\n", w; exit !(NR > 3600 && w < 1e-8) }' "$tmp/$f.p.csv" >"$tmp/w" &&
            { pass; [ -z "${VERBOSE:-}" ] || echo "cam $f: $(cat "$tmp/w")"; } ||
            fail "cam $f: mech cam's profile is $(cat "$tmp/w") off the disc"
    fi
done

# '{points: [...]}' is the list's other spelling: the same table
sed 's/^    profile: \(.*\)/    profile: {points: \1}/' "$tmp/tr.yaml" >"$tmp/trp.yaml"
run "points map" 0 "$MECH" solve "$tmp/trp.yaml" -o "$tmp/trp.csv" &&
    { cmp -s "$tmp/trp.csv" "$tmp/tr.csv" && pass || fail "points map: not the list's table"; }

# the oscillating flat face from A to B: C's distance from its line is 40
# mm; its rate and acceleration with the line's normal n = J (B - A) / |B - A|
disc "$OSC_FLAT" '    follower: follower
    contact: flat-faced
    face: [A, B]' A,B >"$tmp/of.yaml"
if run "oscillating flat" 0 "$MECH" solve "$tmp/of.yaml" -o "$tmp/of.csv"; then
    awk -F, 'BEGIN { PI = atan2(0, -1); w = 2 * PI; e = 0.010; worst = 0 }
        NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
        function v(n) { return $col[n] }
        { q = v("q [rad]"); c[0] = e * cos(q); c[1] = e * sin(q)
          vc[0] = -e * w * sin(q); vc[1] = e * w * cos(q); ac[0] = -e * w * w * cos(q); ac[1] = -e * w * w * sin(q)
          split("x y", X, " ")
          for (i = 0; i < 2; i++) { a[i] = v("A." X[i + 1] " [m]") - c[i]; b[i] = v("B." X[i + 1] " [m]") - c[i]
              va[i] = v("A.v" X[i + 1] " [m/s]") - vc[i]; vb[i] = v("B.v" X[i + 1] " [m/s]") - vc[i]
              aa[i] = v("A.a" X[i + 1] " [m/s^2]") - ac[i]; ab[i] = v("B.a" X[i + 1] " [m/s^2]") - ac[i] }
          L = sqrt((b[0] - a[0])^2 + (b[1] - a[1])^2)
          n[0] = -(b[1] - a[1]) / L; n[1] = (b[0] - a[0]) / L
          dn[0] = -(vb[1] - va[1]) / L; dn[1] = (vb[0] - va[0]) / L
          ddn[0] = -(ab[1] - aa[1]) / L; ddn[1] = (ab[0] - aa[0]) / L
          d = a[0] * n[0] + a[1] * n[1]; if (d < 0) { s = -1; d = -d } else s = 1
          k[1] = (d - 0.040) / 0.040
          k[2] = s * (va[0] * n[0] + va[1] * n[1] + a[0] * dn[0] + a[1] * dn[1]) / (0.040 * w)
          k[3] = s * (aa[0] * n[0] + aa[1] * n[1] + 2 * (va[0] * dn[0] + va[1] * dn[1]) + a[0] * ddn[0] + a[1] * ddn[1]) / (0.040 * w * w)
          for (i = 1; i <= 3; i++) { x = k[i] < 0 ? -k[i] : k[i]; if (x > m[i]) m[i] = x } }
        END { printf "%.2g %.2g %.2g\n", m[1], m[2], m[3]; exit !(NR > 70 && m[1] < 1e-9 && m[2] < 1e-6 && m[3] < 1e-3) }' "$tmp/of.csv" >"$tmp/w" &&
        { pass; [ -z "${VERBOSE:-}" ] || echo "oscillating flat: $(cat "$tmp/w")"; } || fail "oscillating flat: the face's distance from C, its rate, acceleration off by $(cat "$tmp/w")"
fi

# 2. the profile of a program's cam, read back: the program's motion.
# roundtrip EXAMPLE: the example with 'profile: {file: ...}' for its
# program and base radius, against its golden, each column over its scale
roundtrip() {
    "$MECH" cam "$D/$1.yaml" --step 0.1 -o "$tmp/$1.profile.csv" >/dev/null 2>&1
    awk -v f="$1.profile.csv" '
        skip && (/^ *$/ || match($0, /^ */) && RLENGTH > ind) { next }
        { skip = 0 }
        /^ *program:/ { match($0, /^ */); ind = RLENGTH; skip = 1; printf "%*sprofile: {file: %s}\n", ind, "", f; next }
        /^ *base_radius:/ { next }
        { print }' "$D/$1.yaml" >"$tmp/$1.yaml"
    run "roundtrip $1" 0 "$MECH" solve "$tmp/$1.yaml" -o "$tmp/$1.csv" || return
    awk -F, 'NR == FNR { if (FNR > 1) for (i = 1; i <= NF; i++) g[FNR, i] = $i; next }
        FNR == 1 { for (i = 1; i <= NF; i++) name[i] = $i; next }
        { for (i = 2; i <= NF; i++) { e = $i - g[FNR, i]; if (e < 0) e = -e; if (e > err[i]) err[i] = e
              s = g[FNR, i] < 0 ? -g[FNR, i] : g[FNR, i]; if (s > scale[i]) scale[i] = s } ; n = NF }
        END { for (i = 2; i <= n; i++) { r = scale[i] > 0 ? err[i] / scale[i] : err[i]
                  o = name[i] ~ /\.a|alpha|\.ddd/ ? 2 : name[i] ~ /\.v|omega/ ? 1 : 0
                  if (r > worst[o]) worst[o] = r }
              printf "%.2g %.2g %.2g\n", worst[0], worst[1], worst[2]
              exit !(n > 2 && worst[0] < 1e-9 && worst[1] < 1e-7 && worst[2] < 1e-4) }' \
        "tests/golden/cams/$1.csv" "$tmp/$1.csv" >"$tmp/w" &&
        { pass; [ -z "${VERBOSE:-}" ] || echo "roundtrip $1: $(cat "$tmp/w")"; } || fail "roundtrip $1: positions, velocities, accelerations off the program's by $(cat "$tmp/w") of their scales"
}
roundtrip translating-roller
roundtrip oscillating-flat
roundtrip cam-fourbar

# 3. the generated code evaluates the same cubic pieces: bit for bit
run "jit" 0 "$MECH" solve "$tmp/or.yaml" --jit -o "$tmp/orj.csv" &&
    { cmp -s "$tmp/or.csv" "$tmp/orj.csv" && pass || fail "jit: a profile's cam not bit for bit"; }

# the fuzzer's seed (tests/cams/points.yaml): the disc as 24 points (15
# deg apart), the errors 15^4 (distance), 15^3 (rate) and 15^2
# (acceleration) times those of 360 points: 1.1e-5, 7.1e-4, 3.2e-2
if run "seed" 0 "$MECH" solve tests/cams/points.yaml -o "$tmp/seed.csv"; then
    contact "seed (24 points)" 0.008 "$tmp/seed.csv" 2e-5 1.5e-3 6e-2
fi

# errors at their place (a file that cannot be read: exit 3)
bad() {  # LABEL PATTERN SED-SCRIPT [STATUS]: tr.yaml edited, then mech check
    sed "$3" "$tmp/tr.yaml" >"$tmp/bad.yaml"
    run "$1" "${4:-2}" "$MECH" check "$tmp/bad.yaml" && has_line "$tmp/err" "$2" "$1: message"
}
bad3() { bad "$@" 3; }
bad "program and profile" "bad.yaml:[0-9]*:5: error: a cam has 'program' (the follower's lift, the profile derived) or 'profile' (its points, the lift derived), not both" 's/^    profile:/    program: {segments: [{dwell: 360 deg}]}\n    profile:/'
bad "base radius and profile" "bad.yaml:[0-9]*:5: error: a cam given by its 'profile' has the base circle of the profile" 's/^    roller_radius: 8 mm/    roller_radius: 8 mm\n    base_radius: 30 mm/'
bad "centre outside" "bad.yaml:[0-9]*:5: error: cam 'disc': the cam's centre (its pivot O at 70, 0 mm) is not inside its profile" 's/^      O: \[0, 0\]$/      O: [70, 0]/; s/^  O: \[0, 0\]/  O: [70, 0]/'
bad "too few" "bad.yaml:[0-9]*:14: error: cam 'disc': a profile needs at least 8 points around the cam, not 3" 's/^    profile: .*/    profile: [[40, 0], [0, 40], [-40, 0]]/'
bad "twice around" "bad.yaml:[0-9]*:5: error: cam 'disc': the profile's points go 2 times around the cam's centre" 's/^    profile: .*/    profile: [[40, 0], [0, 40], [-40, 0], [0, -40], [40, 0.1], [0, 40.1], [-40, 0.1], [0, -40.1]]/'
bad "repeated point" "error: cam 'disc': profile points 8 and 9 are at one place" 's/^    profile: .*/    profile: [[40, 0], [30, 30], [0, 40], [-30, 30], [-40, 0], [-30, -30], [0, -40], [30, -30], [30, -30]]/'
bad "not a point" "bad.yaml:[0-9]*:[0-9]*: error: a profile point is \[x, y\], not 3 numbers" 's/^    profile: \[\[/    profile: [[1, /'
printf 'x [mm],y [mm]\n40,0\n30,30\n0,40\n-30,30\n-40,zero\n' >"$tmp/p.csv"
bad "csv not a number" "p.csv:6:2: error: not a number in the profile's y column" 's/^    profile: .*/    profile: {file: p.csv}/'
printf 'a,b\n1,2\n' >"$tmp/p.csv"
bad "csv columns" "error: cam 'disc': '.*p.csv' has no columns profile.x and profile.y (mech cam's) or x and y" 's/^    profile: .*/    profile: {file: p.csv}/'
bad "profile both" "bad.yaml:[0-9]*:14: error: a profile is '{points: \[\[x, y\], ...\]}' or '{file: CSV}' (columns profile.x and profile.y, as mech cam writes, or x and y), not both" 's/^    profile: \(.*\)/    profile: {file: p.csv, points: \1}/'
bad "profile neither" "bad.yaml:[0-9]*:14: error: a profile is '{points: \[\[x, y\], ...\]}' or '{file: CSV}'" 's/^    profile: .*/    profile: {}/'
bad "profile key" "bad.yaml:[0-9]*:[0-9]*: error: unknown key 'pts'" 's/^    profile: .*/    profile: {pts: 1}/'
bad3 "csv missing" "error: cam 'disc': the profile '.*nope.csv' cannot be read" 's/^    profile: .*/    profile: {file: nope.csv}/'
printf 'x [s],y [mm]\n' >"$tmp/p.csv"
bad "csv unit" "error: cam 'disc': the profile's x column of '.*p.csv' is in 's', not a length" 's/^    profile: .*/    profile: {file: p.csv}/'
bad "line misses" "error: the follower's line (slider 'y_R') passes 60 mm from the cam's centre O, not inside the base circle plus the roller (38 mm)" 's/^  T: \[5, 0\]/  T: [60, 0]/'

summary
