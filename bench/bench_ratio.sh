#!/bin/sh
# bench/bench_ratio.sh: the targets of issue 21 as ratios to the hand-written
# solvers of bench/bench_hand.c, in instructions per driver step counted by
# callgrind (noise-free on a shared machine): a sweep of 3600 steps minus one
# of 360, over 3240, inside mech_solve (the interpreter, set-up excluded) or
# hand_sweep. Needs valgrind; without it, says so and stops (the timed ratios
# are in bench-hand's table).
#
# For a target not met, the cause column comes from the profile of that very
# run (the interpreter's 3600-step sweep, callgrind_annotate, self cost per
# function): the three largest shares of the step by kind of work, and the
# instructions per step they stand for. docs/performance.md ("Why target 1
# is not met") reads them.
#   sh bench/bench_ratio.sh [build/bench/bench-hand]
HAND=${1:-build/bench/bench-hand}
TARGET=1.5
if ! command -v valgrind >/dev/null 2>&1; then
    echo "instructions per step: valgrind not installed, not measured (see the timed table of bench-hand)"
    exit 0
fi
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bench_ratio.XXXXXX") || exit 1
trap 'rm -rf "$TMP"' EXIT INT TERM
# instructions in function $1 for: bench-hand --count ARGS... (the profile
# kept in $TMP/profile when $PROFILE is set)
count() {
    fn=$1; shift
    out=/dev/null
    [ -n "$PROFILE" ] && out=$TMP/profile
    valgrind --tool=callgrind --toggle-collect="$fn" --callgrind-out-file="$out" \
        "$HAND" --count "$@" 2>&1 >/dev/null | awk '/Collected/ { print $4 }'
}
per_step() {  # fn, name, side [forces]
    fn=$1; shift
    a=$(count "$fn" "$1" "$2" 3600 $3)
    b=$(PROFILE= count "$fn" "$1" "$2" 360 $3)
    [ -n "$a" ] && [ -n "$b" ] || { echo "?"; return; }
    echo $(( (a - b) / 3240 ))
}
# The cause, from $TMP/profile (3600 steps): self instructions by kind of
# work, the three largest as "kind share% (instructions per step)".
cause() {
    [ -s "$TMP/profile" ] || { echo "(no profile)"; return; }
    callgrind_annotate "$TMP/profile" 2>/dev/null | awk '
    /^ *[0-9,]+ +\( *[0-9.]+%\) / {
        n = $1; gsub(",", "", n); f = $0; sub(/^ *[0-9,]+ +\( *[0-9.]+%\) +/, "", f)
        if (f ~ /PROGRAM TOTALS/) { total = n; next }
        k = "other"
        if (f ~ /run_range|tape_run/) k = "tape dispatch"
        else if (f ~ /sincos|s_sin|s_cos|fenv_private|__sin|__cos/) k = "sin/cos"
        else if (f ~ /blocklu|linsys|linear_solve|equilibrate|:factor|inverse_norm|whole_solve|block_solve|klu_/) k = "LU+condition"
        else if (f ~ /solver_newton|:evaluate|solver_step_size|vec_norm_inf|solver_rates|:condition/) k = "Newton loop"
        else if (f ~ /kin_|place_at|on_link|solver_publish/) k = "link frames+points"
        else if (f ~ /cont_|columns_|fill_row|accept|mech_table|predict|:row_|solve_row/) k = "continuation+rows"
        else if (f ~ /forces_|springs_|friction/) k = "forces"
        else if (f ~ /mem(cpy|move|set)/) k = "copies"
        s[k] += n }
    END {
        if (!total) { print "(no profile)"; exit }
        out = ""
        for (i = 0; i < 3; i++) {
            best = ""; for (k in s) if (best == "" || s[k] > s[best]) best = k
            if (best == "") break
            out = out sprintf("%s%s %d%% (%d)", out == "" ? "" : ", ", best,
                              100 * s[best] / total + 0.5, s[best] / 3600 + 0.5)
            delete s[best]
        }
        print out }'
}
row() {  # name, interpreter, hand-written
    awk -v n="$1" -v i="$2" -v h="$3" -v t="$TARGET" -v c="$4" 'BEGIN {
        r = h > 0 ? i / h : 0
        printf "%-20s %11d %11d %6.2f  %-7s  %s\n", n, i, h, r, r <= t ? "met" : "not met",
               r <= t ? "" : c }'
}
echo "issue 21, target 1: instructions per driver step (callgrind, 3600 - 360 steps over the"
echo "file's range; positions, velocities, accelerations; tol 1e-12), interpreter (mech_solve)"
echo "against the hand-written Newton solver (bench-hand); target: ratio <= $TARGET. Cause: the"
echo "interpreter's own profile of the 3600-step run, largest kinds of work (share, instr/step)"
printf '%-20s %11s %11s %6s  %-7s  %s\n' mechanism interpreter hand-written ratio target cause
for name in fourbar offset-slider-crank conveyor stirling; do
    i=$(PROFILE=1 per_step mech_solve "$name" interp) c=$(cause)
    h=$(PROFILE= per_step hand_sweep "$name" hand)
    row "$name" "$i" "$h" "$c"
done
i=$(PROFILE=1 per_step mech_solve conveyor interp forces) c=$(cause)
h=$(PROFILE= per_step hand_sweep conveyor hand forces)
row conveyor+forces "$i" "$h" "$c"
echo "(conveyor+forces: joint reactions and driver torque, friction off; the hand-written"
echo "force solver assembles the 15 x 15 Newton-Euler system densely and factors it by dense LU)"
echo "(the interpreter does the hand-written solver's Newton work, 1.0 iterations and two"
echo "factorisations per step; the excess is spread over the general code path's kinds of work,"
echo "none above about a fifth: docs/performance.md, \"Why target 1 is not met\")"
