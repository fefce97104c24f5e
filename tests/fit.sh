#!/bin/sh
# tests/fit.sh: mech fit (docs/synthesis.md) against known answers. The
# targets are solved from a known four-bar (tests/fit/fourbar.yaml: r 20,
# l 60, b 50, d 70 mm, P at 40 mm and 30 deg from AB); a copy with some
# dimensions changed must fit back to the known ones: path generation (P.x,
# P.y), function generation (the rocker's angle against the crank's; and
# at three precision points against Freudenstein's equation solved here),
# motion generation (P and the coupler's angle); a bound that excludes the
# answer gives the bound and a residual, honestly reported; targets no
# mechanism within the bounds reaches give exit 1 and no file; the file
# written solves to the targets and keeps the comments; bad input.
# Run from the repository root:  MECH=build/mech sh tests/fit.sh
NAME=fit . tests/lib.sh
F=tests/fit/fourbar.yaml

# value NAME FILE: the number of parameter NAME's line in FILE
value() { sed -n "s/^  $1: \\({value: \\)\\{0,1\\}\\([-0-9.e+]*\\).*/\\2/p" "$2"; }
# near A B TOL: |A - B| <= TOL
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(a != "" && d <= t) }'; }

# the targets: 12 crank angles of the known mechanism, in the file's units
"$MECH" solve "$F" --from 0 --to 330 --steps 11 --outputs P,rocker,coupler --level positions \
    --units file -o "$tmp/all.csv" 2>/dev/null || fail "solve the targets"
cut -d, -f1-3 "$tmp/all.csv" >"$tmp/path.csv"
cut -d, -f1,4 "$tmp/all.csv" >"$tmp/function.csv"
cut -d, -f1-3,5 "$tmp/all.csv" >"$tmp/motion.csv"
has_line "$tmp/path.csv" '^q \[deg\],P.x \[mm\],P.y \[mm\]$' "targets: the path's header"
has_line "$tmp/function.csv" '^q \[deg\],rocker.angle \[deg\]$' "targets: the function's header"
has_line "$tmp/motion.csv" '^q \[deg\],P.x \[mm\],P.y \[mm\],coupler.angle \[deg\]$' "targets: the motion's header"
# the generator itself against a closed form: at q = 90 deg, A = (0, 20);
# B is where the circles |B - A| = 60 and |B - C| = 50 meet, above AC
# (turn A -> B -> C clockwise); P = A + 40 mm along AB turned by 30 deg
awk -F, 'NR == 5 {
    ax = 0; ay = 20; cx = 70; cy = 0; l = 60; b = 50
    dx = cx - ax; dy = cy - ay; dd = sqrt(dx * dx + dy * dy)
    a = (l * l - b * b + dd * dd) / (2 * dd); h = sqrt(l * l - a * a)
    mx = ax + a * dx / dd; my = ay + a * dy / dd
    bx = mx - h * dy / dd; by = my + h * dx / dd
    t = atan2(by - ay, bx - ax) + atan2(1, 1) * 4 / 6
    px = ax + 40 * cos(t); py = ay + 40 * sin(t)
    d = ($2 - px) ^ 2 + ($3 - py) ^ 2
    exit !($1 > 90 - 1e-9 && $1 < 90 + 1e-9 && d < 1e-20)
}' "$tmp/path.csv" && pass || fail "the targets at q = 90 deg are not the four-bar's P by hand"

# 1. path generation: three dimensions changed by 10 % or less, recovered
sed -e 's/^  r: 20 mm/  r: 22 mm/' -e 's/^  l: 60 mm/  l: 55 mm/' -e 's/^  b: 50 mm/  b: 53 mm/' \
    "$F" >"$tmp/moved.yaml"
if run "path" 0 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/path.csv" -o "$tmp/best.yaml"; then
    near "$(value r "$tmp/best.yaml")" 20 1e-6 && pass || fail "path: r = $(value r "$tmp/best.yaml"), expected 20"
    near "$(value l "$tmp/best.yaml")" 60 1e-6 && pass || fail "path: l = $(value l "$tmp/best.yaml"), expected 60"
    near "$(value b "$tmp/best.yaml")" 50 1e-6 && pass || fail "path: b = $(value b "$tmp/best.yaml"), expected 50"
    obj=$(sed -n 's/^objective *\([^ ]*\).*/\1/p' "$tmp/out")
    near "$obj" 0 1e-20 && pass || fail "path: objective $obj, expected about 0"
    has_line "$tmp/out" '^solves  *[1-9][0-9]* ' "path: the number of solves"
    has_line "$tmp/out" '^stopped      converged: .* (lmder info [1-4])$' "path: lmder converged"
    has_line "$tmp/out" '^time  *[0-9.e+-]* s$' "path: the time"
    has_line "$tmp/out" '^  P.x  *worst error [0-9.e+-]* mm (at q = [0-9.]* deg)' "path: the worst error"
    # 4. the file written: comments kept, only the three values changed, and
    # it solves to the targets
    has_line "$tmp/best.yaml" '^  r: 20 mm  *# crank O-A$' "best: r's line with its comment"
    has_line "$tmp/best.yaml" '^# A crank-rocker four-bar with its dimensions' "best: the header comment"
    [ "$(diff "$tmp/moved.yaml" "$tmp/best.yaml" | grep -c '^>')" -eq 3 ] && pass ||
        fail "best: $(diff "$tmp/moved.yaml" "$tmp/best.yaml" | grep -c '^>') lines changed, expected 3"
    if run "best solves" 0 "$MECH" solve "$tmp/best.yaml" --from 0 --to 330 --steps 11 --outputs P \
        --level positions --units file -o "$tmp/best.csv"; then
        run "best meets the targets" 0 "$MECH" compare "$tmp/best.csv" "$tmp/path.csv" --rtol 0 --atol 1e-6 && pass
    fi
fi

# parameters in a flow mapping: only the values inside the braces change
sed -e 's/^parameters:$/parameters: {r: 22 mm, l: 55 mm, b: 53 mm, d: 70 mm, e: 40 mm, phi: 30 deg}/' \
    -e '/^  [rlbde]: /d' -e '/^  phi: /d' "$tmp/moved.yaml" >"$tmp/flow.yaml"
if run "flow parameters" 0 "$MECH" fit "$tmp/flow.yaml" --free r,l,b --target "$tmp/path.csv" -o "$tmp/flow-best.yaml"; then
    has_line "$tmp/flow-best.yaml" '^parameters: {r: 20 mm, l: 60 mm, b: 50 mm, d: 70 mm, e: 40 mm, phi: 30 deg}$' \
        "flow parameters: the values replaced"
fi

# the same from 8 (QUICK: 4) starts on 2 threads, within bounds
n=8; [ "${MECH_QUICK:-}" = 1 ] && n=4
if run "path, bounded starts" 0 "$MECH" fit "$tmp/moved.yaml" --free r=15:25,l=50:70,b=40:60 \
    --target "$tmp/path.csv" --starts $n -j 2; then
    has_line "$tmp/out" "^starts  *$n ($n assembled" "starts: all assemble"
    has_line "$tmp/out" '^  r  *20 mm   (bounds 15 .. 25 mm)$' "starts: r"
    has_line "$tmp/out" '^  1\. objective [0-9.e-]*: r=20 l=60 b=50$' "starts: the best distinct solution"
fi

# --seed: another set of starts (the Halton points shifted), the same set
# for the same seed; seed 0 is no shift
for sd in 0 7 7; do
    "$MECH" fit "$tmp/moved.yaml" --free r=15:25,l=50:70,b=40:60 --target "$tmp/path.csv" \
        --starts 4 --seed $sd -j $((sd % 3 + 1)) 2>&1 | grep -v '^time' >"$tmp/seed$sd.$$" || true
    [ -f "$tmp/seed7.first" ] || { [ "$sd" = 7 ] && mv "$tmp/seed7.$$" "$tmp/seed7.first"; }
done
"$MECH" fit "$tmp/moved.yaml" --free r=15:25,l=50:70,b=40:60 --target "$tmp/path.csv" \
    --starts 4 -j 2 2>&1 | grep -v '^time' >"$tmp/noseed"
cmp -s "$tmp/seed0.$$" "$tmp/noseed" && pass || fail "--seed 0 is not the unshifted starts"
cmp -s "$tmp/seed7.first" "$tmp/seed7.$$" && pass || fail "--seed 7 twice gave two results"
grep '^solves' "$tmp/seed7.first" >"$tmp/s7"; grep '^solves' "$tmp/noseed" >"$tmp/s0"
cmp -s "$tmp/s7" "$tmp/s0" && fail "--seed 7 ran the same starts as no seed ($(cat "$tmp/s0"))" || pass
has_line "$tmp/seed7.first" '^  r  *20 mm   (bounds 15 .. 25 mm)$' "--seed 7: the same solution"
run "--seed -1" 2 "$MECH" fit "$tmp/moved.yaml" --free r=15:25 --target "$tmp/path.csv" --seed -1 &&
    has_line "$tmp/err" "seed" "--seed -1: the message names the option"

# 2. function generation: the rocker's angle against the crank's
if run "function" 0 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/function.csv" -o "$tmp/fn.yaml"; then
    near "$(value r "$tmp/fn.yaml")" 20 1e-6 && pass || fail "function: r = $(value r "$tmp/fn.yaml")"
    near "$(value l "$tmp/fn.yaml")" 60 1e-6 && pass || fail "function: l = $(value l "$tmp/fn.yaml")"
    near "$(value b "$tmp/fn.yaml")" 50 1e-6 && pass || fail "function: b = $(value b "$tmp/fn.yaml")"
    has_line "$tmp/out" '^  rocker.angle worst error [0-9.e+-]* deg' "function: the error in degrees"
fi

# function generation against Freudenstein's equation at three precision
# points (an exact solution): the input angles phi 30, 90, 150 deg and the
# output angles psi of the four-bar r 20, l 60, b 50, d 70 mm computed here
# by the circle intersection; Freudenstein's K1 cos(psi) - K2 cos(phi) + K3
# = cos(phi - psi) with K1 = d/r, K2 = d/b, K3 = (r^2 - l^2 + b^2 + d^2) /
# (2 r b) solved for K (Cramer's rule) gives the lengths with d fixed; mech
# fit from 10 % off must find those
awk 'BEGIN {
    pi = atan2(0, -1); r = 20; l = 60; b = 50; d = 70
    print "q [deg],rocker.angle [deg]"
    for (i = 0; i < 3; i++) {
        f = (30 + 60 * i) * pi / 180; ax = r * cos(f); ay = r * sin(f)
        dx = d - ax; dy = -ay; dd = sqrt(dx * dx + dy * dy)
        a = (l * l - b * b + dd * dd) / (2 * dd); h = sqrt(l * l - a * a)
        bx = ax + a * dx / dd - h * dy / dd; by = ay + a * dy / dd + h * dx / dd
        s = atan2(by, bx - d)
        printf "%.17g,%.17g\n", (30 + 60 * i), s * 180 / pi
        F[i] = f; S[i] = s
    }
    # rows: cos(psi) K1 - cos(phi) K2 + K3 = cos(phi - psi)
    for (i = 0; i < 3; i++) { M[i,0] = cos(S[i]); M[i,1] = -cos(F[i]); M[i,2] = 1; R[i] = cos(F[i] - S[i]) }
    det = M[0,0]*(M[1,1]*M[2,2]-M[1,2]*M[2,1]) - M[0,1]*(M[1,0]*M[2,2]-M[1,2]*M[2,0]) + M[0,2]*(M[1,0]*M[2,1]-M[1,1]*M[2,0])
    for (k = 0; k < 3; k++) {
        for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) N[i,j] = (j == k) ? R[i] : M[i,j]
        K[k] = (N[0,0]*(N[1,1]*N[2,2]-N[1,2]*N[2,1]) - N[0,1]*(N[1,0]*N[2,2]-N[1,2]*N[2,0]) + N[0,2]*(N[1,0]*N[2,1]-N[1,1]*N[2,0])) / det
    }
    fr = d / K[0]; fb = d / K[1]; fl = sqrt(fr * fr + fb * fb + d * d - 2 * K[2] * fr * fb)
    printf "%.17g %.17g %.17g\n", fr, fl, fb > "/dev/stderr"
}' >"$tmp/freud.csv" 2>"$tmp/freud.txt"
read -r fr fl fb <"$tmp/freud.txt"
near "$fr" 20 1e-9 && near "$fl" 60 1e-9 && near "$fb" 50 1e-9 && pass ||
    fail "Freudenstein's solution $fr $fl $fb is not the four-bar's 20 60 50"
if run "Freudenstein" 0 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/freud.csv" -o "$tmp/freud.yaml"; then
    near "$(value r "$tmp/freud.yaml")" "$fr" 1e-6 && pass || fail "Freudenstein: r = $(value r "$tmp/freud.yaml"), expected $fr"
    near "$(value l "$tmp/freud.yaml")" "$fl" 1e-6 && pass || fail "Freudenstein: l = $(value l "$tmp/freud.yaml"), expected $fl"
    near "$(value b "$tmp/freud.yaml")" "$fb" 1e-6 && pass || fail "Freudenstein: b = $(value b "$tmp/freud.yaml"), expected $fb"
    obj=$(sed -n 's/^objective *\([^ ]*\).*/\1/p' "$tmp/out")
    near "$obj" 0 1e-20 && pass || fail "Freudenstein: objective $obj, expected 0 (an exact solution)"
fi

# free timing: the targets' crank angles given 3-4 deg off, each an
# unknown: the dimensions and the true angles (0, 30, ..., 330) come back;
# with the timing prescribed the same targets leave a residual
awk -F, 'NR == 1 { print; next } { printf "%.10g,%s,%s\n", $1 + ((NR % 2) ? 4 : -3), $2, $3 }' \
    "$tmp/path.csv" >"$tmp/shifted.csv"
if run "prescribed timing, shifted" 0 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/shifted.csv"; then
    obj=$(sed -n 's/^objective *\([^ ]*\).*/\1/p' "$tmp/out")
    near "$obj" 0 1e-8 && fail "prescribed timing: objective $obj, expected a residual" || pass
fi
if run "free timing" 0 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/shifted.csv" --free-timing \
    -o "$tmp/timed.yaml"; then
    near "$(value r "$tmp/timed.yaml")" 20 1e-6 && pass || fail "free timing: r = $(value r "$tmp/timed.yaml")"
    near "$(value l "$tmp/timed.yaml")" 60 1e-6 && pass || fail "free timing: l = $(value l "$tmp/timed.yaml")"
    near "$(value b "$tmp/timed.yaml")" 50 1e-6 && pass || fail "free timing: b = $(value b "$tmp/timed.yaml")"
    sed -n '/^timing/{n;p}' "$tmp/out" | awk '{ for (i = 1; i < NF; i++) { d = $i - 30 * (i - 1); if (d < 0) d = -d; if (d > 1e-6) bad = 1 } } END { exit bad }' &&
        pass || fail "free timing: the angles $(sed -n '/^timing/{n;p}' "$tmp/out")"
fi

# motion generation: P and the coupler's angle; the coupler point's
# distance e ({value:, tolerance:}) and angle phi free with the crank
sed -e 's/^  r: 20 mm/  r: 21 mm/' -e 's/value: 40 mm/value: 37 mm/' -e 's/^  phi: 30 deg/  phi: 34 deg/' \
    "$F" >"$tmp/motion.yaml"
if run "motion" 0 "$MECH" fit "$tmp/motion.yaml" --free r,e,phi --target "$tmp/motion.csv" -o "$tmp/mo.yaml"; then
    near "$(value r "$tmp/mo.yaml")" 20 1e-6 && pass || fail "motion: r = $(value r "$tmp/mo.yaml")"
    near "$(value e "$tmp/mo.yaml")" 40 1e-6 && pass || fail "motion: e = $(value e "$tmp/mo.yaml")"
    near "$(value phi "$tmp/mo.yaml")" 30 1e-6 && pass || fail "motion: phi = $(value phi "$tmp/mo.yaml")"
    has_line "$tmp/mo.yaml" '^  e: {value: 40 mm, tolerance: 0.1 mm}' "motion: e's tolerance kept"
fi

# 3. bounds: r must stay in 21..25 mm, the answer 20 is outside: the fit
# ends on the bound with a residual it reports
if run "bound" 0 "$MECH" fit "$tmp/moved.yaml" --free r=21:25,l=50mm:70mm,b=4cm:6cm \
    --target "$tmp/path.csv" --starts 4 -o "$tmp/bound.yaml"; then
    near "$(value r "$tmp/bound.yaml")" 21 1e-9 && pass || fail "bound: r = $(value r "$tmp/bound.yaml"), expected 21"
    has_line "$tmp/out" '^  r  *21 mm   (bounds 21 .. 25 mm, at the lower bound)$' "bound: said"
    obj=$(sed -n 's/^objective *\([^ ]*\).*/\1/p' "$tmp/out")
    near "$obj" 0 1e-8 && fail "bound: objective $obj, expected a residual" || pass
fi
# no mechanism within the bounds assembles at every target: exit 1, no file
sed 's/^  r: 22 mm/  r: 50 mm/' "$tmp/moved.yaml" >"$tmp/far.yaml"
if run "infeasible" 1 "$MECH" fit "$tmp/far.yaml" --free r=45:60 --target "$tmp/path.csv" --starts 4 \
    -o "$tmp/none.yaml"; then
    has_line "$tmp/err" 'no start assembles at every target' "infeasible: message"
    has_line "$tmp/out" '^starts  *4 (0 assembled' "infeasible: the starts"
    [ ! -e "$tmp/none.yaml" ] && pass || fail "infeasible: a file was written"
fi

# the problem in the file's fit: section (the target relative to the file),
# bounds, columns, a weight and the starts from there
cp "$tmp/moved.yaml" "$tmp/section.yaml"
cat >>"$tmp/section.yaml" <<'END'
fit:
  free:
    r: [15 mm, 25 mm]
    l: [5 cm, 7 cm]
    b: ~
  target: path.csv
  columns: [P.x, P.y]
  weights: {P.y: 2}
  starts: 3
END
if run "fit: section" 0 "$MECH" fit "$tmp/section.yaml" -o "$tmp/sbest.yaml"; then
    near "$(value r "$tmp/sbest.yaml")" 20 1e-6 && pass || fail "fit: section: r = $(value r "$tmp/sbest.yaml")"
    near "$(value b "$tmp/sbest.yaml")" 50 1e-6 && pass || fail "fit: section: b = $(value b "$tmp/sbest.yaml")"
    has_line "$tmp/out" '^starts  *3 (3 assembled' "fit: section: starts"
    has_line "$tmp/out" '^  l  *60 mm   (bounds 50 .. 70 mm)$' "fit: section: l's bounds"
    has_line "$tmp/sbest.yaml" '^  weights: {P.y: 2}$' "fit: section: kept in the file written"
fi
sed 's/^    r: \[15 mm, 25 mm\]/    rr: [15 mm, 25 mm]/' "$tmp/section.yaml" >"$tmp/section-bad.yaml"
run "fit: section, not a parameter" 2 "$MECH" fit "$tmp/section-bad.yaml" &&
    has_line "$tmp/err" "section-bad.yaml:[0-9]*:5: error: fit: 'rr' is not one of the file's parameters" "fit: section: message"

# constraints that steer (docs/synthesis.md 4): the known dimensions (l / r
# = 3) violate l / r >= 3.2, so the fit must end on that boundary; there it
# is the fit of the file with l written 3.2 r (the boundary itself) and r, b
# free, to 1e-8 mm. The Grashof condition r + d <= l + b holds with a margin.
cp "$tmp/moved.yaml" "$tmp/ratio.yaml"
cat >>"$tmp/ratio.yaml" <<'END'
fit:
  constraints:
    - "l / r >= 3.2"            # a link ratio the known answer (3) violates
    - r + d <= l + b            # Grashof, the crank the shortest: it turns
END
sed 's/^  l: 55 mm .*/  l: 3.2 * r/' "$tmp/moved.yaml" >"$tmp/ratio-sub.yaml"
if run "ratio" 0 "$MECH" fit "$tmp/ratio.yaml" --free r,l,b --target "$tmp/path.csv" -o "$tmp/ratio-best.yaml"; then
    rr=$(value r "$tmp/ratio-best.yaml") rl=$(value l "$tmp/ratio-best.yaml") rb=$(value b "$tmp/ratio-best.yaml")
    near "$(awk -v l="$rl" -v r="$rr" 'BEGIN { printf "%.17g", l / r }')" 3.2 1e-9 && pass ||
        fail "ratio: l / r = $rl / $rr, expected 3.2 (on the boundary)"
    has_line "$tmp/out" '^  l / r >= 3.2  *margin -\{0,1\}[0-9.e+-]*   (active: on the boundary)$' "ratio: its margin"
    has_line "$tmp/out" '^  r + d <= l + b  *margin 23.19[0-9]* mm$' "ratio: Grashof's margin"
    has_line "$tmp/out" '^starts  *1 (1 assembled at every target within the constraints, 0 rejected, 0 of them violating a constraint)$' "ratio: starts"
    if run "ratio, on the boundary" 0 "$MECH" fit "$tmp/ratio-sub.yaml" --free r,b --target "$tmp/path.csv" -o "$tmp/ratio-sub-best.yaml"; then
        near "$rr" "$(value r "$tmp/ratio-sub-best.yaml")" 1e-8 && pass ||
            fail "ratio: r = $rr, on the boundary $(value r "$tmp/ratio-sub-best.yaml")"
        near "$rb" "$(value b "$tmp/ratio-sub-best.yaml")" 1e-8 && pass ||
            fail "ratio: b = $rb, on the boundary $(value b "$tmp/ratio-sub-best.yaml")"
    fi
fi
# the transmission angle between coupler and rocker, at least 60 deg at
# every target (the known four-bar's least is 53.13 deg, at q = 0): the
# written mechanism solved at the targets' angles must keep it; at least
# 10 deg is inactive and changes nothing
cp "$tmp/moved.yaml" "$tmp/trans.yaml"
printf 'fit:\n  transmission: {links: [coupler, rocker], min: 60 deg}\n' >>"$tmp/trans.yaml"
if run "transmission" 0 "$MECH" fit "$tmp/trans.yaml" --free r=15:25,l=50:70,b=40:60 --starts 4 \
    --target "$tmp/path.csv" -o "$tmp/trans-best.yaml"; then
    has_line "$tmp/out" '^  transmission coupler/rocker margin -\{0,1\}[0-9.e+-]* deg (least 60 deg, at q = 0 deg)$' "transmission: its margin"
    "$MECH" solve "$tmp/trans-best.yaml" --from 0 --to 330 --steps 11 --outputs rocker,coupler \
        --level positions --units file -o "$tmp/trans.csv" 2>/dev/null || fail "transmission: solve the result"
    awk -F, 'NR > 1 { d = ($3 - $2) * atan2(1, 1) / 45; s = sin(d); if (s < 0) s = -s
                      mu = atan2(s, sqrt(1 - s * s)) * 45 / atan2(1, 1); if (mu < least) least = mu }
             BEGIN { least = 90 } END { exit !(least >= 60 - 1e-6 && least <= 60 + 1e-6) }' \
        "$tmp/trans.csv" && pass || fail "transmission: the result's least angle is not 60 deg"
    obj=$(sed -n 's/^objective *\([^ ]*\).*/\1/p' "$tmp/out")
    near "$obj" 0 1e-8 && fail "transmission: objective $obj, expected a residual" || pass
fi
# --transmission states the same on the command line: the same answer
if run "--transmission" 0 "$MECH" fit "$tmp/moved.yaml" --free r=15:25,l=50:70,b=40:60 --starts 4 \
    --target "$tmp/path.csv" --transmission coupler,rocker,60deg -o "$tmp/trans-opt.yaml"; then
    for n in r l b; do
        near "$(value $n "$tmp/trans-opt.yaml")" "$(value $n "$tmp/trans-best.yaml")" 1e-9 && pass ||
            fail "--transmission: $n = $(value $n "$tmp/trans-opt.yaml"), the section's $(value $n "$tmp/trans-best.yaml")"
    done
fi
run "--transmission, not a link" 2 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/path.csv" \
    --transmission coupler,crankk,60 -o "$tmp/x.yaml" &&
    has_line "$tmp/err" "error: transmission: 'crankk' is not a moving link of the file" "--transmission, not a link: message"
run "--transmission, 95 deg" 2 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/path.csv" \
    --transmission coupler,rocker,95deg -o "$tmp/x.yaml" &&
    has_line "$tmp/err" "the least angle must lie between 0 and 90 deg, not '95deg'" "--transmission, 95 deg: message"
run "--transmission, no angle" 2 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/path.csv" \
    --transmission coupler,rocker -o "$tmp/x.yaml" &&
    has_line "$tmp/err" "transmission needs LINK,LINK,MIN" "--transmission, no angle: message"
sed 's/min: 60 deg/min: 10 deg/' "$tmp/trans.yaml" >"$tmp/trans10.yaml"
if run "transmission, inactive" 0 "$MECH" fit "$tmp/trans10.yaml" --free r,l,b --target "$tmp/path.csv" \
    -o "$tmp/trans10-best.yaml"; then
    near "$(value r "$tmp/trans10-best.yaml")" 20 1e-6 && pass || fail "transmission, inactive: r"
    has_line "$tmp/out" '^  transmission coupler/rocker margin 43.130[0-9]* deg (least 53.130[0-9]* deg, at q = 0 deg)$' "transmission, inactive: margin"
fi
# both kinds at once, with free timing: the ratio and the transmission
# (least 55 deg) end on their boundaries, each margin within its tolerance
cp "$tmp/moved.yaml" "$tmp/both.yaml"
printf 'fit:\n  constraints: ["l / r >= 3.1"]\n  transmission: {links: [coupler, rocker], min: 55 deg}\n' >>"$tmp/both.yaml"
if run "constraints, free timing" 0 "$MECH" fit "$tmp/both.yaml" --free r,l,b --target "$tmp/path.csv" --free-timing; then
    has_line "$tmp/out" '^  l / r >= 3.1  *margin -\{0,1\}[0-9.]*e-1[0-9]   (active: on the boundary)$' "free timing: the ratio on its boundary"
    has_line "$tmp/out" '^  transmission coupler/rocker margin -\{0,1\}[0-9.]*e-1[0-9] deg (least 55 deg' "free timing: the transmission on its boundary"
fi
# a constraint no mechanism within the bounds meets: every start rejected
# (never reported as a solution), exit 1, no file
cp "$tmp/moved.yaml" "$tmp/never.yaml"
printf 'fit:\n  constraints: ["r >= 30 mm"]\n' >>"$tmp/never.yaml"
if run "constraint never met" 1 "$MECH" fit "$tmp/never.yaml" --free r=15:25,l,b --starts 3 \
    --target "$tmp/path.csv" -o "$tmp/never-best.yaml"; then
    has_line "$tmp/out" '^starts  *3 (0 assembled at every target within the constraints, 3 rejected, 3 of them violating a constraint)$' "never met: starts"
    has_line "$tmp/err" 'no start assembles at every target within the constraints' "never met: message"
    [ ! -e "$tmp/never-best.yaml" ] && pass || fail "never met: a file was written"
fi
# bad constraints: the file, line and column of the problem, exit 2, no file
bad_constraint() {  # LABEL CONSTRAINT COLUMN MESSAGE
    cp "$tmp/moved.yaml" "$tmp/badc.yaml"
    printf 'fit:\n  constraints:\n    - %s\n' "$2" >>"$tmp/badc.yaml"
    run "constraint: $1" 2 "$MECH" fit "$tmp/badc.yaml" --free r,l,b --target "$tmp/path.csv" -o "$tmp/x.yaml" &&
        has_line "$tmp/err" "badc.yaml:43:$3: error: fit: constraint $4" "constraint: $1: message"
}
bad_constraint "unknown name" '"l / rr >= 3"' 12 "'l / rr >= 3': unknown name 'rr'"
bad_constraint "mixed units" 'l + phi <= 3 mm' 9 "'l + phi <= 3 mm': cannot add a length (m) and an angle (rad) (both sides"
bad_constraint "mixed sides" '"l <= 3 kg"' 10 "'l <= 3 kg': cannot subtract a length (m) and a mass (kg)"
bad_constraint "no comparison" '"l + r"' 7 "'l + r' is not an inequality"
bad_constraint "two comparisons" 'l <= r <= b' 14 "'l <= r <= b' has more than one comparison"
cp "$tmp/moved.yaml" "$tmp/badc.yaml"
printf 'fit:\n  transmission: {links: [coupler, crankk], min: 30 deg}\n' >>"$tmp/badc.yaml"
run "transmission: not a link" 2 "$MECH" fit "$tmp/badc.yaml" --free r,l,b --target "$tmp/path.csv" -o "$tmp/x.yaml" &&
    has_line "$tmp/err" "badc.yaml:42:35: error: fit: transmission: 'crankk' is not a moving link of the file" "transmission: not a link: message"

# a constraint the unconstrained optimum violates: targets of a four-bar
# whose crank cannot turn fully (r 45 mm: s + l = 45 + 70 > 60 + 50, not
# Grashof), over the part of the turn where it assembles. Free r finds 45;
# with --whole-range (a full turn) every fit is rejected (or one that turns)
sed 's/^  r: 20 mm/  r: 45 mm/' "$F" >"$tmp/ng.yaml"
"$MECH" solve "$tmp/ng.yaml" --from 0 --to 60 --steps 6 --outputs P --level positions --units file \
    -o "$tmp/ng.csv" 2>/dev/null || fail "solve the non-Grashof targets"
sed 's/^  r: 45 mm/  r: 30 mm/' "$tmp/ng.yaml" >"$tmp/ng30.yaml"
run "unconstrained" 0 "$MECH" fit "$tmp/ng30.yaml" --free r=15:48 --target "$tmp/ng.csv" --starts 3 &&
    has_line "$tmp/out" '^  r  *45 mm ' "unconstrained: r 45"
"$MECH" fit "$tmp/ng30.yaml" --free r=15:48 --target "$tmp/ng.csv" --starts 3 --whole-range \
    -o "$tmp/ng-best.yaml" >"$tmp/out" 2>"$tmp/err"
case $? in
1) has_line "$tmp/err" 'no start assembles at every target and over the whole range' "whole range: message"
   [ ! -e "$tmp/ng-best.yaml" ] && pass || fail "whole range: a file was written" ;;
0) "$MECH" solve "$tmp/ng-best.yaml" -o "$tmp/ng-best.csv" 2>/dev/null && pass ||
       fail "whole range: the solution does not turn fully" ;;
*) fail "whole range: exit status $?" ;;
esac

# --plot: the targets as points, the fitted curve and the start's over the
# file's range, one SVG. check_plot SVG CSV COLS: well-formed XML, one
# marker of class "dot" per target and each where the target is on the
# page (data-mech-transform: a path, x and y in mm; data-mech-axes: a
# column against the driver in deg), two curves (fitted, start dashed)
check_plot() {
    python3 - "$@" <<'EOF'
import csv, math, sys
import xml.dom.minidom
svg, targets, ncols = sys.argv[1], sys.argv[2], int(sys.argv[3])
ncurves = int(sys.argv[4]) if len(sys.argv) > 4 else 2
try:
    doc = xml.dom.minidom.parse(svg)
except Exception as e:
    print(f"FAIL: {svg}: not well-formed XML: {e}")
    sys.exit(1)
root = doc.documentElement
rows = [[float(v) for v in r] for r in list(csv.reader(open(targets)))[1:]]
dots = [u for u in doc.getElementsByTagName("use") if u.getAttribute("class") == "dot"]
page = [(float(u.getAttribute("x")), float(u.getAttribute("y"))) for u in dots]
if ncols == 2:  # a path: x, y in mm; the transform is for metres
    s, ox, oy = (float(v) for v in root.getAttribute("data-mech-transform").split())
    want = [(ox + s * r[1] / 1e3, oy - s * r[2] / 1e3) for r in rows]
else:  # against the driver: deg and the column's display unit
    sx, ox, sy, oy = (float(v) for v in root.getAttribute("data-mech-axes").split())
    want = [(ox + sx * r[0], oy - sy * r[1]) for r in rows]
bad = []
if len(page) != len(rows):
    bad.append(f"{len(page)} target markers for {len(rows)} targets")
worst = max((math.hypot(a[0] - b[0], a[1] - b[1]) for a, b in zip(page, want)), default=0)
if worst > 0.01:
    bad.append(f"a target marker {worst:.3f} px from its target")
curves = [p for p in doc.getElementsByTagName("path") if p.getAttribute("stroke")
          and p.getAttribute("d").startswith("M") and p.parentNode.getAttribute("clip-path")]
if len(curves) != ncurves or (ncurves == 2 and not curves[1].getAttribute("stroke-dasharray")):
    bad.append(f"{len(curves)} curves, expected the fitted one and the start's dashed"
               if ncurves == 2 else f"{len(curves)} curves, expected the file's one")
if ncurves == 1 and ncols == 2:  # the file's own curve meets every target (an exact fit)
    import re
    pts = [tuple(map(float, m)) for m in re.findall(r"(-?[0-9.]+),(-?[0-9.]+)",
                                                     curves[0].getAttribute("d"))]
    def seg(a, p, q):  # the distance from a to the segment pq
        dx, dy = q[0] - p[0], q[1] - p[1]
        t = ((a[0] - p[0]) * dx + (a[1] - p[1]) * dy) / (dx * dx + dy * dy or 1)
        t = min(1, max(0, t))
        return math.hypot(a[0] - p[0] - t * dx, a[1] - p[1] - t * dy)
    far = max(min(seg(a, p, q) for p, q in zip(pts, pts[1:])) for a in want)
    if far > 0.6:
        bad.append(f"a target {far:.2f} px from the file's curve")
title = doc.getElementsByTagName("title")[0].firstChild.data
if f"{len(rows)} targets" not in title:
    bad.append(f"title '{title}' does not count the targets")
for b in bad:
    print(f"FAIL: {svg}: {b}")
sys.exit(1 if bad else 0)
EOF
}
if run "plot: path" 0 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/path.csv" --plot "$tmp/fit.svg"; then
    has_line "$tmp/out" "^plotted      $tmp/fit.svg\$" "plot: path: said"
    check_plot "$tmp/fit.svg" "$tmp/path.csv" 2 && pass || fail "plot: path: the figure"
fi
if run "plot: function" 0 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/function.csv" \
    --plot "$tmp/fn.svg" -o "$tmp/fn2.yaml"; then
    check_plot "$tmp/fn.svg" "$tmp/function.csv" 1 && pass || fail "plot: function: the figure"
    [ -s "$tmp/fn2.yaml" ] && pass || fail "plot: function: -o not written with --plot"
fi
# mech plot and mech report of a file with a fit: section: its own curve
# against the section's targets (STEM-fit.svg, a figure of the page). The
# fitted file's curve meets every target; the unfitted one's misses some
# (the same check, so it can fail); targets that cannot be read leave the
# figure out with a warning, the other figures written.
if run "plot: fitted file" 0 "$MECH" plot "$tmp/sbest.yaml" --out "$tmp/figs"; then
    has_line "$tmp/out" "^$tmp/figs/sbest-fit.svg\$" "plot: fitted file: said"
    check_plot "$tmp/figs/sbest-fit.svg" "$tmp/path.csv" 2 1 && pass || fail "plot: fitted file: the figure"
fi
if run "plot: unfitted file" 0 "$MECH" plot "$tmp/section.yaml" --out "$tmp/figs"; then
    check_plot "$tmp/figs/section-fit.svg" "$tmp/path.csv" 2 1 >"$tmp/check" &&
        fail "plot: unfitted file: its curve meets the targets" ||
        has_line "$tmp/check" "px from the file's curve" "plot: unfitted file: the miss found"
fi
if run "report: fitted file" 0 "$MECH" report "$tmp/sbest.yaml" -o "$tmp/fit.html"; then
    has_line "$tmp/fit.html" "<title[^>]*>Fit: the path of P through 12 targets</title>" "report: the fit's figure"
fi
mkdir -p "$tmp/lone"
cp "$tmp/section.yaml" "$tmp/lone/section.yaml"
if run "plot: targets missing" 0 "$MECH" plot "$tmp/lone/section.yaml" --out "$tmp/lone"; then
    has_line "$tmp/err" "lone/path.csv: warning: the fit: section's figure is left out: cannot open" "plot: targets missing: warning"
    [ ! -e "$tmp/lone/section-fit.svg" ] && [ -s "$tmp/lone/section-path-P.svg" ] && pass ||
        fail "plot: targets missing: the fit figure written or the others not"
fi
run "report: targets missing" 0 "$MECH" report "$tmp/lone/section.yaml" -o "$tmp/lone.html" &&
    has_line "$tmp/lone.html" "figure is left out" "report: targets missing: said on the page"
cp "$tmp/moved.yaml" "$tmp/keep.yaml"
run "plot over the input" 2 "$MECH" fit "$tmp/moved.yaml" --free r --target "$tmp/path.csv" --plot "$tmp/moved.yaml" &&
    has_line "$tmp/err" "is the input file" "plot over the input: message"
run "plot over the targets" 2 "$MECH" fit "$tmp/moved.yaml" --free r --target "$tmp/path.csv" --plot "$tmp/path.csv" &&
    has_line "$tmp/err" "is the input file" "plot over the targets: message"
cmp -s "$tmp/moved.yaml" "$tmp/keep.yaml" && pass || fail "plot: the input changed"
run "plot and -o the same" 2 "$MECH" fit "$tmp/moved.yaml" --free r --target "$tmp/path.csv" --plot "$tmp/same" -o "$tmp/same" &&
    has_line "$tmp/err" "name the same file" "plot and -o the same: message"
[ ! -e "$tmp/same" ] && pass || fail "plot and -o the same: a file was written"
run "plot: no such folder" 3 "$MECH" fit "$tmp/moved.yaml" --free r,l,b --target "$tmp/path.csv" --plot "$tmp/no/fit.svg" &&
    has_line "$tmp/err" "$tmp/no/fit.svg" "plot: no such folder: message"
[ ! -e "$tmp/no" ] && pass || fail "plot: no such folder: something written"
run "plot: no solution" 1 "$MECH" fit "$tmp/far.yaml" --free r=45:60 --target "$tmp/path.csv" --starts 2 \
    --plot "$tmp/none.svg" && { [ ! -e "$tmp/none.svg" ] && pass || fail "plot: no solution: a plot was written"; }

# bad input: each a precise message, exit 2, no file written
sed '1s/P.x/Q.x/' "$tmp/path.csv" >"$tmp/unknown.csv"
run "unknown column" 2 "$MECH" fit "$tmp/moved.yaml" --free r --target "$tmp/unknown.csv" -o "$tmp/x.yaml" &&
    has_line "$tmp/err" "'Q' is not a point, moving link or slider" "unknown column: message"
run "not a parameter" 2 "$MECH" fit "$tmp/moved.yaml" --free r,zz --target "$tmp/path.csv" -o "$tmp/x.yaml" &&
    has_line "$tmp/err" "no parameter 'zz' in the file (its parameters: r, l, b, d, e, phi)" "not a parameter: message"
sed '1s/P.x \[mm\]/P.x [deg]/' "$tmp/path.csv" >"$tmp/units.csv"
run "wrong unit" 2 "$MECH" fit "$tmp/moved.yaml" --free r --target "$tmp/units.csv" -o "$tmp/x.yaml" &&
    has_line "$tmp/err" "column 'P.x' is in 'deg', where mech solve's is in m" "wrong unit: message"
run "velocity column" 2 "$MECH" fit "$tmp/moved.yaml" --free r --target "$tmp/path.csv" --column P.vx -o "$tmp/x.yaml" &&
    has_line "$tmp/err" "no such column" "velocity column: message"
run "bounds exclude the start" 2 "$MECH" fit "$tmp/moved.yaml" --free r=10:15 --target "$tmp/path.csv" -o "$tmp/x.yaml" &&
    has_line "$tmp/err" ":7:3: error: the bounds 10:15 of 'r' exclude its value in the file (22 mm)" "bounds: message"
run "no --free" 2 "$MECH" fit "$tmp/moved.yaml" --target "$tmp/path.csv" &&
    has_line "$tmp/err" "free NAME,... is needed" "no --free: message"
run "output over the input" 2 "$MECH" fit "$tmp/moved.yaml" --free r --target "$tmp/path.csv" -o "$tmp/moved.yaml" &&
    has_line "$tmp/err" "is the input file" "output over the input: message"
[ ! -e "$tmp/x.yaml" ] && pass || fail "bad input: a file was written"
cmp -s "$tmp/moved.yaml" "$tmp/far.yaml" && fail "the input changed" || pass

summary
