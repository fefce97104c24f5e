#!/bin/sh
# tests/dynamics.sh: forward dynamics, `mech simulate` (docs/dynamics.md),
# against independent truths:
#   1. a compound pendulum: its period against the closed form (small
#      swings: 2 pi sqrt(I_O / (m g d)); large ones: the exact period with
#      the complete elliptic integral, by the arithmetic-geometric mean),
#      and its energy, constant to 1e-8 of itself;
#   2. a slider-crank run up from rest by a constant torque, no gravity:
#      the kinetic energy is the torque's work T (theta - theta0), from the
#      CSV's own angle column;
#   3. a crank-rocker released under gravity: energy kept to 1e-9;
#      a five-bar with two free cranks swinging under gravity: energy kept;
#      with one crank's law of time and the other free, the energy balance
#      closes with the work of the prescribed driver; a pendulum on linear
#      and torsion spring-dampers: the springs' energy and the dampers' work
#      close it too;
#   4. a free crank under a stiff speed controller (a load of its own
#      omega) reproduces the torque `mech solve --forces` gives the same
#      crank at that constant speed; and that torque (checked against its
#      closed form), fed back as a load of time, holds the crank at the
#      constant speed to the integration's tolerance;
#   5. the shaper run up from rest by a motor law with the flywheel `mech
#      solve --speed-fluctuation 0.02` sizes: the simulated steady speed
#      fluctuation against that 0.02 (the sizing is an estimate: 10 %); the
#      Stirling engine run up by its gas forces against a fan, the same;
#   6. the shipped examples (mechanisms/dynamics/) against their goldens;
# and the command line: help, bad options, a file with no free driver,
# friction refused, the output never replacing an input, a stop at a
# singular position with the rows so far.
# Run from the repository root:  MECH=build/mech sh tests/dynamics.sh
NAME=dynamics . tests/lib.sh
D=tests/dynamics

# col FILE NAME: the 1-based column of header cell "NAME [unit]"
col() { head -n 1 "$1" | tr ',' '\n' | grep -n "^$2 \[" | cut -d: -f1; }

# within LABEL VALUE LIMIT: pass when |VALUE| <= LIMIT
within() {
    if [ -z "$2" ]; then
        fail "$1: no value"
    elif awk -v v="$2" -v l="$3" 'BEGIN { if (v < 0) v = -v; exit !(v <= l) }'; then
        pass
    else
        fail "$1: $2, expected at most $3 in size"
    fi
}

# the period of bar.angle's swing about -90 deg, from its upward crossings
# (linear interpolation: the angle's curvature vanishes there)
period() {
    awk -F, -v c="$(col "$1" bar.angle)" 'BEGIN { pi = 3.14159265358979323846 }
        NR > 1 { t = $1; y = $c + pi / 2
                 if (NR > 2 && yp < 0 && y >= 0) {
                     tc = tp - yp * (t - tp) / (y - yp)
                     if (n == 0) first = tc
                     last = tc; n++
                 }
                 tp = t; yp = y }
        END { printf "%.15g\n", (n > 1 ? (last - first) / (n - 1) : -1) }' "$1"
}

# the exact period of the pendulum of pendulum.yaml (L = 0.5 m, g = 9.81)
# swinging to A degrees from the vertical: T0 / AGM(1, cos(A/2))
exact_period() {
    awk -v a="$1" 'BEGIN { pi = 3.14159265358979323846
        T0 = 2 * pi * sqrt(2 * 0.5 / (3 * 9.81)); th = a * pi / 180
        x = 1; y = cos(th / 2)
        for (i = 0; i < 40; i++) { m = (x + y) / 2; y = sqrt(x * y); x = m }
        printf "%.15g\n", a == 0 ? T0 : T0 / x }'
}

# largest |energy.balance| over the largest |energy or work| column
balance_ratio() {
    awk -F, -v b="$(col "$1" energy.balance)" 'NR > 1 {
            v = $b < 0 ? -$b : $b; if (v > w) w = v
            for (i = b - 6; i < b; i++) { e = $i < 0 ? -$i : $i; if (e > s) s = e } }
        END { printf "%.3g\n", (s > 0 ? w / s : 1) }' "$1"
}

# ---- 1. the compound pendulum ------------------------------------------------

sed 's/value: -80 deg/value: -89 deg/' $D/pendulum.yaml >"$tmp/small.yaml"
if run "pendulum, 1 deg swing" 0 "$MECH" simulate "$tmp/small.yaml" --to 5s --step 1ms --rtol 1e-10 --atol 1e-12 -o "$tmp/small.csv"; then
    p=$(period "$tmp/small.csv")
    t0=$(exact_period 0)
    # the closed form of small swings; a 1 deg swing is 1.9e-5 slower
    within "small swing: period $p against 2 pi sqrt(I_O/(m g d)) = $t0" "$(awk -v p="$p" -v t="$t0" 'BEGIN { print (p - t) / t }')" 3e-5
    within "1 deg swing: period $p against the exact" "$(awk -v p="$p" -v t="$(exact_period 1)" 'BEGIN { print (p - t) / t }')" 1e-8
fi

ANGLES="60 150"
[ "${MECH_QUICK:-}" = 1 ] && ANGLES=150
for a in $ANGLES; do
    sed "s/value: -80 deg/value: $((a - 90)) deg/" $D/pendulum.yaml >"$tmp/large.yaml"
    if run "pendulum, $a deg swing" 0 "$MECH" simulate "$tmp/large.yaml" --to 6s --step 1ms --rtol 1e-11 --atol 1e-13 -o "$tmp/large.csv"; then
        p=$(period "$tmp/large.csv")
        within "$a deg swing: period $p against the exact $(exact_period $a)" "$(awk -v p="$p" -v t="$(exact_period $a)" 'BEGIN { print (p - t) / t }')" 1e-8
        within "$a deg swing: energy balance" "$(balance_ratio "$tmp/large.csv")" 1e-8
        # kinetic + potential is constant: the balance column says so, and so
        # do the energy columns summed here
        within "$a deg swing: T + V drift" "$(awk -F, -v k="$(col "$tmp/large.csv" energy.kinetic)" 'NR == 2 { e0 = $k + $(k + 1) } NR > 1 { d = $k + $(k + 1) - e0; if (d < 0) d = -d; if (d > w) w = d; g = $(k + 1) < 0 ? -$(k + 1) : $(k + 1); if (g > s) s = g } END { print w / s }' "$tmp/large.csv")" 1e-8
    fi
done
# Adams gives the same motion
if run "pendulum, adams" 0 "$MECH" simulate $D/pendulum.yaml --method adams --to 4s --rtol 1e-10 --atol 1e-12 --step 1ms -o "$tmp/adams.csv"; then
    within "adams: period" "$(awk -v p="$(period "$tmp/adams.csv")" -v t="$(exact_period 10)" 'BEGIN { print (p - t) / t }')" 1e-7
fi

# released from rest at 10 deg, the pendulum is at rest again half a period
# later, at the other extreme: CVODE's root finding on the rate
if run "pendulum --stop-at-rest" 0 "$MECH" simulate $D/pendulum.yaml --stop-at-rest --rtol 1e-10 --atol 1e-12 -o "$tmp/rest.csv"; then
    has_line "$tmp/err" "note: stopped at rest: the rate of 'bar' crossed zero at t = 0.5802" "stop at rest: the note"
    within "stop at rest: the half period" "$(awk -F, -v h="$(exact_period 10)" 'END { print ($1 - h / 2) / h }' "$tmp/rest.csv")" 1e-8
    within "stop at rest: the other extreme, -100 deg" "$(awk -F, -v c="$(col "$tmp/rest.csv" bar.angle)" 'END { print $c + 100 * 3.14159265358979323846 / 180 }' "$tmp/rest.csv")" 1e-8
fi

# --stop-when: the pendulum passes the vertical a quarter period after release
if run "pendulum --stop-when bar.angle=-90" 0 "$MECH" simulate $D/pendulum.yaml --stop-when "bar.angle=-90" --rtol 1e-10 --atol 1e-12 -o "$tmp/when.csv"; then
    has_line "$tmp/err" "note: stopped: the condition bar.angle=-90 was met at t = 0.2901" "stop when: the note"
    within "stop when: the quarter period" "$(awk -F, -v h="$(exact_period 10)" 'END { print ($1 - h / 4) / h }' "$tmp/when.csv")" 1e-8
fi
run "--stop-when on a rate" 2 "$MECH" simulate $D/pendulum.yaml --stop-when "bar.omega=1" -o "$tmp/x.csv" &&
    has_line "$tmp/err" "'bar.omega' is not a point's x or y, a moving link's angle or a slider's s" "stop when: a rate refused"

# ---- 2. a slider-crank run up by a constant torque, no gravity ---------------

if run "slider-crank run-up" 0 "$MECH" simulate $D/slider-crank-torque.yaml --rtol 1e-10 --atol 1e-12 -o "$tmp/sc.csv" --stats; then
    a=$(col "$tmp/sc.csv" crank.angle)
    k=$(col "$tmp/sc.csv" energy.kinetic)
    # T = 0.5 N*m from theta0 = 30 deg: KE = T (theta - theta0) at every row
    within "run-up: kinetic energy against T (theta - theta0)" "$(awk -F, -v a="$a" -v k="$k" 'NR > 1 { w = 0.5 * ($a - 0.5235987755982988); d = ($k - w) / (w > 1e-3 ? w : 1e-3); if (d < 0) d = -d; if (d > m) m = d } END { print m + 0 }' "$tmp/sc.csv")" 1e-6
    # and it turned: at least five turns in 0.5 s
    within "run-up: the crank turned" "$(awk -F, -v a="$a" 'END { print (($a > 31.4) ? 0 : 1) }' "$tmp/sc.csv")" 0
    # a free driver needs no load: its column is 0 to rounding
    within "run-up: the free driver's load" "$(awk -F, -v c="$(col "$tmp/sc.csv" crank.torque)" 'NR > 1 { v = $c < 0 ? -$c : $c; if (v > m) m = v } END { print m + 0 }' "$tmp/sc.csv")" 1e-8
    has_line "$tmp/err" "simulated to t = 0.5 s, 101 rows" "--stats: the summary"
fi

# ---- 3. two free cranks; a law of time and a free crank ----------------------

if run "five-bar, two free cranks" 0 "$MECH" simulate mechanisms/dynamics/five-bar-free.yaml --to 2s --rtol 1e-10 -o "$tmp/fb.csv"; then
    within "five-bar: energy balance" "$(balance_ratio "$tmp/fb.csv")" 1e-8
    within "five-bar: crank1 swings" "$(awk -F, -v c="$(col "$tmp/fb.csv" crank1.angle)" 'NR == 2 { lo = hi = $c } NR > 1 { if ($c < lo) lo = $c; if ($c > hi) hi = $c } END { print ((hi - lo > 0.5) ? 0 : 1) }' "$tmp/fb.csv")" 0
    within "five-bar: crank2 swings" "$(awk -F, -v c="$(col "$tmp/fb.csv" crank2.angle)" 'NR == 2 { lo = hi = $c } NR > 1 { if ($c < lo) lo = $c; if ($c > hi) hi = $c } END { print ((hi - lo > 0.5) ? 0 : 1) }' "$tmp/fb.csv")" 0
fi
sed 's/^  - {link: crank1, free: true.*/  - {link: crank1, angle: "90 deg + 3 rad\/s * t"}/' mechanisms/dynamics/five-bar-free.yaml >"$tmp/mixed.yaml"
if run "five-bar, crank1 a law, crank2 free" 0 "$MECH" simulate "$tmp/mixed.yaml" --rtol 1e-10 -o "$tmp/mixed.csv"; then
    # crank1 follows its law exactly
    within "mixed: crank1's law" "$(awk -F, -v c="$(col "$tmp/mixed.csv" crank1.angle)" 'NR > 1 { d = $c - (1.5707963267948966 + 3 * $1); if (d < 0) d = -d; if (d > m) m = d } END { print m + 0 }' "$tmp/mixed.csv")" 1e-12
    within "mixed: energy balance with the driver's work" "$(balance_ratio "$tmp/mixed.csv")" 1e-8
    within "mixed: the prescribed driver works" "$(awk -F, -v c="$(col "$tmp/mixed.csv" work.drivers)" 'END { print (($c != 0) ? 0 : 1) }' "$tmp/mixed.csv")" 0
fi

# the crank-rocker released under gravity whirls round: energy kept to 1e-9
# with tight tolerances (Adams: the motion is not stiff)
if run "four-bar under gravity" 0 "$MECH" simulate mechanisms/dynamics/pendulum-fourbar.yaml --method adams --rtol 1e-11 --atol 1e-14 -o "$tmp/fb4.csv"; then
    within "four-bar: energy balance" "$(balance_ratio "$tmp/fb4.csv")" 1e-9
    within "four-bar: the crank turns past a whole turn" "$(awk -F, -v c="$(col "$tmp/fb4.csv" crank.angle)" 'NR == 2 { lo = $c } NR > 1 && $c < lo { lo = $c } END { print ((lo < -3.2) ? 0 : 1) }' "$tmp/fb4.csv")" 0
fi

# springs and dampers: their energy and the dampers' work close the balance
if run "spring pendulum" 0 "$MECH" simulate $D/spring-pendulum.yaml --rtol 1e-10 -o "$tmp/sp.csv"; then
    within "spring pendulum: energy balance with springs and dampers" "$(balance_ratio "$tmp/sp.csv")" 1e-8
    within "spring pendulum: the dampers take energy" "$(awk -F, -v c="$(col "$tmp/sp.csv" work.dampers)" 'END { print (($c < -0.05) ? 0 : 1) }' "$tmp/sp.csv")" 0
    within "spring pendulum: the springs hold energy" "$(awk -F, -v c="$(col "$tmp/sp.csv" energy.springs)" 'NR == 2 { print (($c > 1) ? 0 : 1) }' "$tmp/sp.csv")" 0
fi

# ---- 4. a stiff speed controller reproduces mech solve's torque --------------

sed -e 's/^  - {link: crank, free: true.*/  - {link: crank, free: true, initial: {value: 30 deg, speed: 20 rad\/s}, load: "-K * (crank.omega - 20 rad\/s)"}/' \
    -e 's/^parameters: {\(.*\)}/parameters: {\1, K: 1000 N*m*s\/rad}/' $D/slider-crank-torque.yaml >"$tmp/ctl.yaml"
sed 's/^  - {link: crank, free: true.*/  - {link: crank, angle: "30 deg + 20 rad\/s * t"}/' $D/slider-crank-torque.yaml >"$tmp/law.yaml"
if run "speed controller: simulate" 0 "$MECH" simulate "$tmp/ctl.yaml" --to 0.3s --step 5ms -o "$tmp/ctl.csv" &&
   run "speed controller: solve" 0 "$MECH" solve "$tmp/law.yaml" --forces --from 0 --to 0.3 --steps 60 -o "$tmp/law.csv"; then
    w=$(col "$tmp/ctl.csv" crank.omega)
    tq=$(col "$tmp/law.csv" crank.torque)
    n=$(head -n 1 "$tmp/ctl.csv" | tr ',' '\n' | wc -l)
    # after the first row (the controller starts at 0 torque): -K (omega - 20)
    # against the torque that holds 20 rad/s, to 1e-3 of the largest
    within "speed controller: torque" "$(paste -d, "$tmp/ctl.csv" "$tmp/law.csv" | awk -F, -v w="$w" -v t="$((n + tq))" 'NR > 2 { d = -1000 * ($w - 20) - $t; if (d < 0) d = -d; if (d > e) e = d; a = $t < 0 ? -$t : $t; if (a > m) m = a } END { print e / m }')" 1e-3
fi

# ---- 4b. mech solve's torque fed back as a load of time keeps the speed -----

# constant-speed.yaml: the crank's load is the torque m w^2 x'(q) x''(q) at
# q = q0 + w t. First the truth of that torque: mech solve --forces with the
# crank's law q0 + w t gives it to rounding; then, fed back, it holds the free
# crank at w from q0 (the dynamics about that motion are not damped: errors
# of the integration stay, they are not forgotten) - BDF and Adams, at the
# default tolerances, at rtol 1e-10 and with atol 1e-14 (where CVODE's own
# difference-quotient Jacobian let BDF drift 1e-3).
sed -e 's/^    free: true$/    angle: "q0 + w * t"/' -e '/^    initial: {value: q0/d' -e '/^    # mp (w/,/^outputs:/{/^outputs:/!d;}' \
    $D/constant-speed.yaml >"$tmp/cslaw.yaml"
if run "constant speed: mech solve" 0 "$MECH" solve "$tmp/cslaw.yaml" --forces -o "$tmp/cslaw.csv"; then
    within "constant speed: mech solve's torque against m w^2 x' x''" "$(awk -F, -v c="$(col "$tmp/cslaw.csv" crank.torque)" 'NR > 1 {
            q = 0.523598775598298873 + 20 * $1; r = 0.04; l = 0.14; s = sin(q); k = cos(q)
            D = sqrt(l * l - r * r * s * s)
            xp = -r * s - r * r * s * k / D
            xpp = -r * k - r * r * (k * k - s * s) / D - r ^ 4 * s * s * k * k / D ^ 3
            T = 0.5 * 400 * xp * xpp; d = T - $c; if (d < 0) d = -d; if (d > e) e = d
            a = T < 0 ? -T : T; if (a > m) m = a }
        END { printf "%.3g\n", (NR > 50 && m > 0.1) ? e / m : 1 }' "$tmp/cslaw.csv")" 1e-13
fi
for opts in "--method bdf" "--method adams" "--method bdf --rtol 1e-10" "--method bdf --rtol 1e-8 --atol 1e-14" "--method adams --rtol 1e-10 --atol 1e-12"; do
    if run "constant speed: simulate $opts" 0 "$MECH" simulate $D/constant-speed.yaml $opts -o "$tmp/cs.csv"; then
        r=$(echo "$opts" | sed -n 's/.*--rtol \([^ ]*\).*/\1/p')
        within "constant speed ($opts): crank.omega against 20 rad/s" "$(awk -F, -v w="$(col "$tmp/cs.csv" crank.omega)" -v a="$(col "$tmp/cs.csv" crank.angle)" 'NR > 1 {
                d = ($w - 20) / 20; if (d < 0) d = -d; if (d > e) e = d
                d = $a - (0.523598775598298873 + 20 * $1); if (d < 0) d = -d; if (d > e) e = d }
            END { printf "%.3g\n", NR == 102 ? e : 1 }' "$tmp/cs.csv")" "$(awk -v r="${r:-1e-8}" 'BEGIN { print 100 * r }')"
    fi
done

# ---- 5. the shaper run up by a motor, with the flywheel sized for Cs = 0.02 --

# mech solve --speed-fluctuation 0.02 sizes the flywheel from the constant-
# speed torque (an estimate); the simulated steady fluctuation over the last
# two turns is that within 10 % (0.0205 measured), at about 60 rpm
if run "shaper run-up" 0 "$MECH" simulate mechanisms/dynamics/shaper-runup.yaml --step 10ms -o "$tmp/shaper.csv" &&
   run "shaper: the flywheel estimate" 0 "$MECH" solve mechanisms/shaper.yaml --speed-fluctuation 0.02 -o "$tmp/s.csv"; then
    has_line "$tmp/err" "inertia 27.77.. kg\*m^2 for a speed fluctuation of 0.02" "shaper: the estimate is the file's flywheel"
    cs=$(awk -F, -v c="$(col "$tmp/shaper.csv" crank.omega)" 'NR > 1 && $1 >= 18 { if (n == 0) lo = hi = $c; n++; s += $c; if ($c < lo) lo = $c; if ($c > hi) hi = $c } END { printf "%.6g %.6g\n", (hi - lo) / (s / n), s / n }' "$tmp/shaper.csv")
    within "shaper: simulated Cs ${cs% *} against 0.02" "$(awk -v c="${cs% *}" 'BEGIN { print (c - 0.02) / 0.02 }')" 0.1
    within "shaper: mean speed ${cs#* } rad/s against 60 rpm" "$(awk -v w="${cs#* }" 'BEGIN { print (w - 6.283185307) / 6.283185307 }')" 0.01
fi

# ---- 5b. the Stirling engine run up by its gas against a fan ----------------

# stirling-runup.yaml: the gas forces of stirling-gas.yaml drive the free
# crank, a fan load Tm (w/w0)^2 brakes it, and the flywheel is the one mech
# solve --speed-fluctuation 0.02 sizes at 300 rpm. From 150 rpm the engine
# runs up to about 300 rpm; the steady fluctuation over the last two turns
# against the 0.02 (0.0201 measured, at 299.9 rpm)
sed '/^outputs:/,$d' mechanisms/dynamics/stirling-runup.yaml >"$tmp/sr.yaml"
printf 'outputs:\n  links: [crank]\n' >>"$tmp/sr.yaml"
if run "Stirling run-up" 0 "$MECH" simulate "$tmp/sr.yaml" --to 90s --step 1ms -o "$tmp/sr.csv" &&
   run "Stirling: the flywheel estimate" 0 "$MECH" solve mechanisms/stirling-gas.yaml --speed-fluctuation 0.02 -o "$tmp/sg.csv"; then
    has_line "$tmp/err" "inertia 0.212927 kg\*m^2 for a speed fluctuation of 0.02" "Stirling: the estimate is the file's flywheel"
    cs=$(awk -F, -v c="$(col "$tmp/sr.csv" crank.omega)" 'NR > 1 && $1 >= 89.6 { if (n == 0) lo = hi = $c; n++; s += $c; if ($c < lo) lo = $c; if ($c > hi) hi = $c } END { printf "%.6g %.6g\n", (hi - lo) / (s / n), s / n }' "$tmp/sr.csv")
    within "Stirling: simulated Cs ${cs% *} against 0.02" "$(awk -v c="${cs% *}" 'BEGIN { print (c - 0.02) / 0.02 }')" 0.05
    within "Stirling: mean speed ${cs#* } rad/s against 300 rpm" "$(awk -v w="${cs#* }" 'BEGIN { print (w - 31.4159265) / 31.4159265 }')" 0.01
    within "Stirling: energy balance" "$(balance_ratio "$tmp/sr.csv")" 1e-4
fi

# ---- 6. the shipped examples against their reviewed goldens -----------------

# tests/golden/dynamics/NAME.csv is `mech simulate mechanisms/dynamics/NAME.yaml
# --rtol 1e-12 --atol 1e-14` (BDF; make golden; tests/golden/README.md).
# Each golden's energy balance closes to 1e-8 of its largest energy or work;
# solved again with those options it matches to 1e-6 (a rounding changed
# anywhere - another libm, SUNDIALS, the order of a sum - moves CVODE's
# step sequence: 1e-8 measured when the 2 x 2 mass matrix's LU changed);
# and another method, Adams at the same
# tolerances, gives the free and dependent coordinates and rates within
# 5e-5 (measured at most 9e-6: the four-bar whirls to 64 rad/s, the
# shaper's cutting force switches on and off).
for f in mechanisms/dynamics/*.yaml; do
    n=$(basename "$f" .yaml)
    g=tests/golden/dynamics/$n.csv
    if [ ! -f "$g" ]; then
        fail "$n: no golden $g (make golden)"
        continue
    fi
    within "golden $n: energy balance" "$(balance_ratio "$g")" 1e-8
    if run "golden $n: simulate" 0 "$MECH" simulate "$f" --rtol 1e-12 --atol 1e-14 -o "$tmp/g.csv"; then
        run "golden $n: compare" 0 "$MECH" compare --rtol 1e-6 --atol 1e-6 "$tmp/g.csv" "$g"
    fi
    cols=$(head -n 1 "$g" | tr ',' '\n' | sed -n 's/^\([A-Za-z0-9_]*\.\(angle\|omega\|s\|v\)\) \[.*/\1/p' | tr '\n' ',' | sed 's/,$//')
    if run "golden $n: Adams" 0 "$MECH" simulate "$f" --method adams --rtol 1e-12 --atol 1e-14 -o "$tmp/a.csv"; then
        run "golden $n: Adams against the golden ($cols)" 0 "$MECH" compare --rtol 1e-6 --atol 5e-5 --columns "$cols" "$tmp/a.csv" "$g"
    fi
done

# ---- the command line ---------------------------------------------------------

run "simulate --help" 0 "$MECH" simulate --help &&
    has_line "$tmp/out" "^usage: mech simulate FILE" "--help: usage" &&
    has_line "$tmp/out" "--method M" "--help: --method"
run "simulate --method rk4" 2 "$MECH" simulate $D/pendulum.yaml --method rk4 &&
    has_line "$tmp/err" "is bdf or adams" "--method: the words"
run "simulate --to 2 m" 2 "$MECH" simulate $D/pendulum.yaml --to "2 m" &&
    has_line "$tmp/err" "^mech simulate: --to: " "--to in metres"
run "simulate a file with no free driver" 2 "$MECH" simulate mechanisms/five-bar.yaml -o "$tmp/x.csv" &&
    has_line "$tmp/err" "nothing to simulate: no driver is free" "no free driver: message"
[ ! -e "$tmp/x.csv" ] && pass || fail "no free driver: an output was written"
sed 's/^  bar:$/  bar:/; s/^drivers:/joints:\n  - {pin: O, links: [ground, bar], friction: 0.1, radius: 5 mm}\ndrivers:/' $D/pendulum.yaml >"$tmp/fric.yaml"
if "$MECH" check "$tmp/fric.yaml" >/dev/null 2>&1; then
    run "friction refused" 2 "$MECH" simulate "$tmp/fric.yaml" -o "$tmp/x.csv" &&
        has_line "$tmp/err" "Coulomb friction, which mech simulate does not model" "friction: message"
fi
cp $D/pendulum.yaml "$tmp/in.yaml"
run "the output is the input" 2 "$MECH" simulate "$tmp/in.yaml" -o "$tmp/in.yaml" &&
    cmp -s "$tmp/in.yaml" $D/pendulum.yaml && pass || fail "the input was changed"
# the units of --to and --step; the rows
if run "simulate --to 500 ms --step 100 ms" 0 "$MECH" simulate $D/pendulum.yaml --to "500 ms" --step "100 ms" -o "$tmp/u.csv"; then
    [ "$(wc -l <"$tmp/u.csv")" -eq 7 ] && pass || fail "--step 100 ms to 500 ms: $(wc -l <"$tmp/u.csv") lines, expected 7"
    has_line "$tmp/u.csv" "^0.5," "--to 500 ms: the last row"
    has_line "$tmp/u.csv" ",energy.kinetic \[J\],energy.gravity \[J\],energy.springs \[J\],work.loads \[J\],work.drivers \[J\],work.dampers \[J\],energy.balance \[J\]\$" "the energy columns"
fi
# a table too large for memory is refused before the run
run "simulate 10^7 rows of the shaper" 2 "$MECH" simulate mechanisms/dynamics/shaper-runup.yaml --to 1000s --step 1e-4 -o "$tmp/x.csv" &&
    has_line "$tmp/err" "the results would take 5.76 GB in memory (10000001 rows of 72 columns)" "too large: message"

# released upside down, the five-bar folds until its arms are in line: the
# run stops there (exit 1), names the loop, and writes the rows before
sed 's/^gravity: .*/gravity: [0, -9.81]/' mechanisms/dynamics/five-bar-free.yaml >"$tmp/fold.yaml"
if run "a singular position stops the run" 1 "$MECH" simulate "$tmp/fold.yaml" -o "$tmp/fold.csv"; then
    has_line "$tmp/err" "error: at t = 0.2[0-9]* s: .*: arm1 and arm2 folded in line; .*loop 1 (P-B-E-O-A-P)" "stop: the time, the links in line and the loop"
    has_line "$tmp/err" "^mech simulate: stopped at t = 0.2" "stop: the summary"
    [ "$(wc -l <"$tmp/fold.csv")" -gt 5 ] && pass || fail "stop: the rows before are not written"
fi
# the other commands see a free driver turning at its initial speed
if run "check a free driver" 0 "$MECH" check mechanisms/dynamics/five-bar-free.yaml; then
    has_line "$tmp/out" "^  driver     angle of link 'crank2' = free, from 60 deg at 2 rad/s$" "check: free"
fi

summary
