#!/bin/sh
# tests/drivers.sh: the command line on drivers as laws of time (`sweep` and
# `drivers`, docs/format.md section 7.3), on mechanisms/five-bar.yaml: what
# `mech check` prints, the t column and one torque per driver of `mech
# solve`, --from/--to in seconds, a gap reported in seconds, the figures and
# the animation against t, the equations' driver rows, and bad input with
# its exit status. The numbers themselves are checked against closed forms
# by tests/unit/test_drivers.c.
# Run from the repository root:  MECH=build/mech sh tests/drivers.sh
NAME=drivers . tests/lib.sh
F=mechanisms/five-bar.yaml

if run "check" 0 "$MECH" check "$F"; then
    has_line "$tmp/out" "^  sweep      time t from 0 s to 1 s, 101 positions\$" "check: the sweep"
    has_line "$tmp/out" "^  driver     angle of link 'crank1' = 90 deg + 360 deg/s \* t\$" "check: driver 1"
    has_line "$tmp/out" "^  driver     angle of link 'crank2' = 60 deg + 20 deg \* sin(2 \* pi \* t / 1 s)\$" "check: driver 2"
    has_line "$tmp/out" "^  mobility   2 = 3\*(5-1) - 2\*5 - 0, drivers 2\$" "check: two drivers"
fi

if run "solve" 0 "$MECH" solve "$F" -o "$tmp/f.csv" --stats; then
    has_line "$tmp/f.csv" "^t \[s\],A.x \[m\]," "solve: the t column first"
    has_line "$tmp/f.csv" ",crank1.torque \[N\*m\],crank2.torque \[N\*m\],power.residual \[-\]\$" "solve: one torque per driver"
    has_line "$tmp/err" "smallest rcond .* s\$" "solve --stats: the position in s"
    [ "$(wc -l <"$tmp/f.csv")" -eq 102 ] && pass || fail "solve: $(wc -l <"$tmp/f.csv") lines, expected 102"
fi

# --from/--to are times; bare numbers are seconds
if run "solve --from --to" 0 "$MECH" solve "$F" --from 0.25 --to "500 ms" --steps 5 --outputs P -o "$tmp/r.csv"; then
    [ "$(sed -n 2p "$tmp/r.csv" | cut -d, -f1)" = 0.25 ] && pass || fail "--from 0.25: first t $(sed -n 2p "$tmp/r.csv" | cut -d, -f1)"
    [ "$(sed -n 7p "$tmp/r.csv" | cut -d, -f1)" = 0.5 ] && pass || fail "--to 500 ms: last t $(sed -n 7p "$tmp/r.csv" | cut -d, -f1)"
    # the driven coordinates are in the table even when the outputs omit them
    has_line "$tmp/r.csv" "^t \[s\],P.x \[m\],.*,crank1.angle \[rad\],.*,crank2.alpha \[rad/s^2\]" "--outputs P: the driven links too"
fi
run "solve --from in metres" 2 "$MECH" solve "$F" --from "1 m" --to 2 -o "$tmp/x.csv" &&
    has_line "$tmp/err" "expected a time" "--from 1 m: message"

# a gap: arms too short for part of the sweep, reported in seconds
sed 's/P: \[60, 0\]/P: [40, 0]/' "$F" >"$tmp/gap.yaml"
if run "solve with a gap" 1 "$MECH" solve "$tmp/gap.yaml" -o "$tmp/gap.csv"; then
    has_line "$tmp/err" "cannot assemble at time = 0.2 s: .*arm1 and arm2 extended in line" "gap: the limit"
    has_line "$tmp/err" "gap: rows 21 to 48 of 101 (driver at 0.200000 s to 0.470000 s)" "gap: in s"
fi

if run "plot" 0 "$MECH" plot "$F" --out "$tmp/figs"; then
    has_line "$tmp/figs/five-bar-driver-torques.svg" "Driver torques" "plot: the drivers' torques"
    has_line "$tmp/figs/five-bar-driver-torques.svg" ">crank2<" "plot: crank2's torque"
    has_line "$tmp/figs/five-bar-points-position.svg" "time t \[s\]" "plot: x axis t"
fi
run "animate" 0 "$MECH" animate "$F" --frame 10 -o "$tmp/a.svg" &&
    has_line "$tmp/a.svg" "driver time = 0.1 s (position 10 of 101)" "animate: the time"

if run "equations" 0 "$MECH" equations "$F"; then
    has_line "$tmp/out" "^input q: t = time" "equations: q is t"
    has_line "$tmp/out" "^  f3 = th_crank1 - (1.570796327 + 6.283185307\*t)    \[driver 'crank1'\]\$" "equations: driver row 1"
    has_line "$tmp/out" "\[driver 'crank2'\]\$" "equations: driver row 2"
fi

# bad input: exit status 2 and file:line:column
printf 'name: x\nground: {O: [0, 0]}\nlinks:\n  crank: {points: {O: [0, 0], A: [1, 0]}}\nsweep: {time: {from: 0, to: 1, steps: 2}}\ndrivers: [{link: crank, angle: "2 m * t"}]\n' >"$tmp/bad.yaml"
run "bad law" 2 "$MECH" check "$tmp/bad.yaml" &&
    has_line "$tmp/err" "bad.yaml:6:33: error: driver 'crank': the law must be an angle of t, not a quantity in m\*s" "bad law: message"
printf 'name: x\nground: {O: [0, 0]}\nlinks:\n  crank: {points: {O: [0, 0], A: [1, 0]}}\ndrivers: [{link: crank, angle: "2 rad/s * t"}]\n' >"$tmp/nosweep.yaml"
run "drivers without sweep" 2 "$MECH" check "$tmp/nosweep.yaml" &&
    has_line "$tmp/err" "nosweep.yaml:5:10: error: 'drivers' needs 'sweep" "drivers without sweep: message"

# two drivers on a gear train: a planetary differential, sun and ring driven
# by laws of time (tests/truths/differential.yaml); the laws differentiated
# by hand and Willis' formula for the carrier and the planet, every row
D=tests/truths/differential.yaml
if run "solve the differential" 0 "$MECH" solve "$D" -o "$tmp/d.csv"; then
    worst=$(awk -F, 'NR > 1 {
        t = $1
        s[0] = 300 * t + 0.5 * sin(20 * t); s[1] = 300 + 10 * cos(20 * t); s[2] = -200 * sin(20 * t)
        r[0] = -50 * t + 2000 * t * t;      r[1] = -50 + 4000 * t;         r[2] = 4000
        for (k = 0; k < 3; k++) {
            c = (20 * s[k] + 100 * r[k]) / 120       # Willis, z_s = 20, z_r = 100
            p = c - 20 / 40 * (s[k] - c)             # the planet, z_p = 40, relative to c
            split("" , want); want[2 + k] = s[k]; want[5 + k] = r[k]; want[8 + k] = c; want[11 + k] = p
            for (col in want) {
                e = ($col - want[col]) / (abs(want[col]) > 1 ? abs(want[col]) : 1)
                if (abs(e) > worst) worst = abs(e)
            }
        }
    }
    function abs(x) { return x < 0 ? -x : x }
    END { printf "%.3g\n", worst }' "$tmp/d.csv")
    awk -v w="$worst" 'BEGIN { exit !(w < 1e-12) }' && pass ||
        fail "differential: worst relative error $worst against Willis and the laws"
    [ "$(wc -l <"$tmp/d.csv")" -eq 402 ] && pass || fail "differential: $(wc -l <"$tmp/d.csv") lines"
fi

# a load that reads the time t of laws of time (docs/format.md 10.2): a
# torque T = 0.5 N*m/s * t on arm1; by virtual work the drivers' power
# changes by -T * omega_arm1 against the same file without it, every row
sed 's|^outputs:|loads:\n  - {torque: "0.5 N*m/s * t", link: arm1}\noutputs:|' "$F" >"$tmp/tload.yaml"
if run "solve with a load of t" 0 "$MECH" solve "$tmp/tload.yaml" -o "$tmp/tl.csv" &&
   run "solve without it" 0 "$MECH" solve "$F" -o "$tmp/t0.csv"; then
    # columns by name: NAME [unit] in the header of the first file
    worst=$(paste -d, "$tmp/tl.csv" "$tmp/t0.csv" | awk -F, 'NR == 1 {
        n = NF / 2
        for (i = 1; i <= n; i++) { split($i, w, " "); c[w[1]] = i }
        next
    } {
        t1 = c["crank1.torque"]; t2 = c["crank2.torque"]
        dp = ($t1 - $(n + t1)) * $c["crank1.omega"] + ($t2 - $(n + t2)) * $c["crank2.omega"]
        want = -0.5 * $c["t"] * $c["arm1.omega"]                 # -T omega_arm1
        e = dp - want; if (e < 0) e = -e
        sc = want < 0 ? -want : want; if (sc < 1e-3) sc = 1e-3
        if (e / sc > worst) worst = e / sc
    } END { printf "%.3g\n", worst }')
    awk -v w="$worst" 'BEGIN { exit !(w < 1e-9) }' && pass ||
        fail "load of t: drivers' power change off by $worst (relative) from -T omega"
fi
run "a load of t with the driver's speed" 2 "$MECH" check "$(sed 's|0.5 N\*m/s \* t|1 N*m * driver.speed|' "$tmp/tload.yaml" >"$tmp/tsp.yaml"; echo "$tmp/tsp.yaml")" &&
    has_line "$tmp/err" "the driver's value is the time t and has no 'speed'" "driver.speed with laws of time: message"

summary
