#!/bin/sh
# tests/programs.sh: motion programs and the richer laws of time on the
# command line (docs/format.md 7.3, docs/motion-programs.md): mech check's
# line for a program, mech solve of tests/programs/*.yaml against closed
# forms (the program's laws with the chain rule; exp, log, tanh and a
# division by an expression of t) and against differences of its own
# positions, the load-time checks (a jump at a boundary, a gap in the
# period) with file:line:column and exit status 2, a law not defined at a
# row's time, and mech codegen bit for bit. The laws themselves are checked
# to 1e-13 by tests/unit/test_programs.c.
# Run from the repository root:  MECH=build/mech sh tests/programs.sh
NAME=programs . tests/lib.sh
D=tests/programs

if run "check program" 0 "$MECH" check "$D/follower.yaml"; then
    has_line "$tmp/out" "^  driver     displacement of slider 'x_B' = program of 144 deg/s \* t + 30 deg, 4 segments\$" "check: the program"
fi

# worst relative error of columns 2-4 (s, v, a) against the closed form
if run "solve follower" 0 "$MECH" solve "$D/follower.yaml" -o "$tmp/f.csv"; then
    awk -F, 'function cyc(u) { return u - sin(2 * PI * u) / (2 * PI) }
        BEGIN { PI = atan2(0, -1); D = PI / 180; w = 144 * D; b = 120 * D; h = 0.020; worst = 0 }
        NR > 1 {
            x = 30 * D + w * $1; x -= 2 * PI * int(x / (2 * PI))
            if (x < b) { u = x / b; s = h * cyc(u); v = h * (1 - cos(2 * PI * u)) / b * w
                         a = h * 2 * PI * sin(2 * PI * u) / (b * b) * w * w }
            else if (x < 180 * D) { s = h; v = 0; a = 0 }
            else if (x < 300 * D) { u = (x - 180 * D) / b
                s = h - h * (10 * u^3 - 15 * u^4 + 6 * u^5)
                v = -h * (30 * u^2 - 60 * u^3 + 30 * u^4) / b * w
                a = -h * (60 * u - 180 * u^2 + 120 * u^3) / (b * b) * w * w }
            else { s = 0; v = 0; a = 0 }
            e = ($2 - 0.010 - s) / h; if (e < 0) e = -e; if (e > worst) worst = e
            e = ($3 - v) / (h * w / b); if (e < 0) e = -e; if (e > worst) worst = e
            e = ($4 - a) / (h * w * w / (b * b)); if (e < 0) e = -e; if (e > worst) worst = e
        }
        END { printf "%.3g\n", worst; exit !(worst < 1e-12) }' "$tmp/f.csv" >"$tmp/w" &&
        pass || fail "follower against the closed form: worst relative error $(cat "$tmp/w")"
fi

if run "solve functions" 0 "$MECH" solve "$D/functions.yaml" -o "$tmp/l.csv"; then
    awk -F, 'BEGIN { worst = 0 }
        NR > 1 { t = $1; e = exp(-t / 2); x = 2 * t; th = (exp(x) - exp(-x)) / (exp(x) + exp(-x)); q = 1 + t * t
            s = 10 * e + 5 * log(1 + t) + 3 * th + 4 / q
            v = -5 * e + 5 / (1 + t) + 6 * (1 - th * th) - 8 * t / (q * q)
            a = 2.5 * e - 5 / ((1 + t) * (1 + t)) - 24 * th * (1 - th * th) + 4 * (6 * t * t - 2) / (q * q * q)
            r = $2 * 1000 - s; if (r < 0) r = -r; if (r > worst) worst = r
            r = $3 * 1000 - v; if (r < 0) r = -r; if (r > worst) worst = r
            r = $4 * 1000 - a; if (r < 0) r = -r; if (r > worst) worst = r }
        END { printf "%.3g\n", worst; exit !(worst < 1e-12) }' "$tmp/l.csv" >"$tmp/w" &&
        pass || fail "exp/log/tanh/division law against the closed form: worst $(cat "$tmp/w") mm"
fi

# the rocker (modified sine and trapezoid of t): its ends, and omega, alpha
# against central differences of its own angles and rates (h = 1 ms: the
# jerk jumps at the joints of the laws' pieces)
if run "solve rocker" 0 "$MECH" solve "$D/rocker.yaml" -o "$tmp/r.csv"; then
    awk -F, 'BEGIN { PI = atan2(0, -1) }
        NR > 1 { t[NR] = $1; th[NR] = $8; om[NR] = $9; al[NR] = $10; n = NR }
        END { bad = 0
            for (i = 3; i < n; i++) {
                h = t[i + 1] - t[i - 1]
                d = (th[i + 1] - th[i - 1]) / h - om[i]; if (d < 0) d = -d; if (d > 1e-4) bad++
                d = (om[i + 1] - om[i - 1]) / h - al[i]; if (d < 0) d = -d; if (d > 0.1) bad++ }
            for (i = 2; i <= n; i++) {
                if (t[i] == 0.4 || t[i] == 0.5) { d = th[i] - 40 * PI / 180; if (d < 0) d = -d; if (d > 1e-14) bad++ }
                if (t[i] == 0.9 || t[i] == 1) { d = th[i] - 10 * PI / 180; if (d < 0) d = -d; if (d > 1e-14) bad++ } }
            exit bad > 0 }' "$tmp/r.csv" && pass || fail "rocker: rates against differences, or its ends"
fi

# load-time checks: a harmonic rise next to a dwell (an acceleration jump)
sed 's/law: cycloidal}/law: harmonic}/' "$D/follower.yaml" >"$tmp/jump.yaml"
if run "acceleration jump" 2 "$MECH" check "$tmp/jump.yaml"; then
    has_line "$tmp/err" "jump.yaml:22:13: error: driver 'x_B': an acceleration jump of 0.00685389 mm/deg^2 (d2s/dx2) at 120 deg between segment 1 (rise, harmonic) and segment 2 (dwell)" "jump: file:line:col, boundary, size"
fi
sed 's/        period: 360 deg/        period: 360 deg\n        continuity: velocity/' "$tmp/jump.yaml" >"$tmp/vel.yaml"
run "continuity: velocity" 0 "$MECH" check "$tmp/vel.yaml" && pass
sed 's/          - {dwell: 60 deg}$/          - {dwell: 50 deg}/' "$D/follower.yaml" >"$tmp/gap.yaml"
if run "a gap" 2 "$MECH" check "$tmp/gap.yaml"; then
    has_line "$tmp/err" "gap.yaml:19:17: error: driver 'x_B': the segments cover 340 deg, not the period 360 deg: a gap of 20 deg after segment 4" "gap: the message"
fi
sed 's/law: 3-4-5}/law: cubic}/' "$D/follower.yaml" >"$tmp/name.yaml"
run "an unknown law" 2 "$MECH" check "$tmp/name.yaml" &&
    has_line "$tmp/err" "name.yaml:23:.*law 'cubic' is no standard law" "unknown law: the message"

# a law not defined at some row: an error naming the time, no rows of NaN
sed 's|4 mm / (1 + t^2 / 1 s^2)|4 mm * log(2 - t / 1 s)|' "$D/functions.yaml" >"$tmp/log.yaml"
if run "log of a negative number" 2 "$MECH" solve "$tmp/log.yaml" -o "$tmp/log.csv"; then
    has_line "$tmp/err" "log.yaml:13:5: error: driver 'x_B': its law is not defined at t = 2 s: log of 0" "log: the time and why"
fi

# mech codegen generates the programs and the functions (rt_law.h, shared
# with the interpreter): its solver's rows are mech solve's bit for bit
# (tolerance 0); mech solve --jit writes the same table
for f in follower functions rocker mixed; do
    dir=$tmp/gen-$f
    mkdir -p "$dir"
    if run "codegen $f" 0 "$MECH" codegen "$D/$f.yaml" -o "$dir/gen.c" --header "$dir/gen.h" --prefix gen &&
            ${CC:-cc} -std=c11 -Wall -Wextra -Werror -pedantic -O2 -I"$dir" -o "$dir/drv" "$dir/gen.c" \
                tests/codegen_driver.c -lm 2>"$dir/cc" &&
            "$MECH" solve "$D/$f.yaml" -q -o "$dir/ref.csv"; then
        "$dir/drv" "$dir/ref.csv" 0 >"$dir/out" 2>&1 && pass ||
            fail "codegen $f: the generated solver against mech solve: $(head -n 2 "$dir/out" "$dir/cc")"
    else
        fail "codegen $f: $(head -n 2 "$tmp/err" "$dir/cc" 2>/dev/null)"
    fi
done
if run "solve --jit" 0 "$MECH" solve --jit "$D/mixed.yaml" -o "$tmp/jit.csv" &&
        run "solve" 0 "$MECH" solve "$D/mixed.yaml" -o "$tmp/int.csv"; then
    cmp -s "$tmp/jit.csv" "$tmp/int.csv" && pass || fail "solve --jit: not the interpreter's table"
    has_line "$tmp/int.csv" "^t \\[s\\],x1.s \\[m\\]" "mixed: both sliders' columns"
fi

# a parameter in a program: each variant its own laws (drivers_same), the
# peak acceleration h 2 pi / beta^2 * w^2 linear in the lift
sed 's/^units: {length: mm, angle: deg}$/units: {length: mm, angle: deg}\nparameters: {lift: 20 mm}/; s/rise: 20 mm,/rise: lift,/; s/return: 20 mm,/return: lift,/' \
    "$D/follower.yaml" >"$tmp/swp.yaml"
if run "sweep a lift" 0 "$MECH" sweep "$tmp/swp.yaml" --vary lift=10:30:3 --metric max:x_B.a -o "$tmp/swp.csv"; then
    awk -F, 'BEGIN { PI = atan2(0, -1); b = 120 * PI / 180; w = 144 * PI / 180; bad = 0 }
        NR > 1 { h = (NR - 1) * 0.010; a = h * 2 * PI / (b * b) * w * w
                 d = ($5 - a) / a; if (d < 0) d = -d; if (d > 1e-6) bad++ }
        END { exit bad > 0 || NR != 4 }' "$tmp/swp.csv" && pass || fail "sweep a lift: $(cat "$tmp/swp.csv")"
fi

run "equations" 0 "$MECH" equations "$D/follower.yaml" &&
    has_line "$tmp/out" "p_x_B''(t)" "equations: the program as p_x_B(t)"
run "equations latex" 0 "$MECH" equations --format latex "$D/follower.yaml" &&
    has_line "$tmp/out" "mathrm{p\\\\_x\\\\_B}''" "equations latex: the name's underscores escaped"

summary
