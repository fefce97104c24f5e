#!/bin/sh
# bench/bench_ratio.sh: the targets of issue 21 as ratios to the hand-written
# solvers of bench/bench_hand.c, in instructions per driver step counted by
# callgrind (noise-free on a shared machine): a sweep of 3600 steps minus one
# of 360, over 3240, inside mech_solve (the interpreter, set-up excluded) or
# hand_sweep. Needs valgrind; without it, says so and stops (the timed ratios
# are in bench-hand's table).
#   sh bench/bench_ratio.sh [build/bench/bench-hand]
HAND=${1:-build/bench/bench-hand}
TARGET=1.5
if ! command -v valgrind >/dev/null 2>&1; then
    echo "instructions per step: valgrind not installed, not measured (see the timed table of bench-hand)"
    exit 0
fi
# instructions in function $1 for: bench-hand --count ARGS...
count() {
    fn=$1; shift
    valgrind --tool=callgrind --toggle-collect="$fn" --callgrind-out-file=/dev/null \
        "$HAND" --count "$@" 2>&1 >/dev/null | awk '/Collected/ { print $4 }'
}
per_step() {  # fn, name, side [forces]
    fn=$1; shift
    a=$(count "$fn" "$1" "$2" 3600 $3) b=$(count "$fn" "$1" "$2" 360 $3)
    [ -n "$a" ] && [ -n "$b" ] || { echo "?"; return; }
    echo $(( (a - b) / 3240 ))
}
echo "issue 21, target 1: instructions per driver step (callgrind, 3600 - 360 steps over the"
echo "file's range; positions, velocities, accelerations; tol 1e-12), interpreter (mech_solve)"
echo "against the hand-written Newton solver (bench-hand); target: ratio <= $TARGET"
printf '%-22s %12s %12s %7s  %s\n' mechanism interpreter hand-written ratio target
for name in fourbar offset-slider-crank conveyor stirling; do
    i=$(per_step mech_solve "$name" interp) h=$(per_step hand_sweep "$name" hand)
    awk -v n="$name" -v i="$i" -v h="$h" -v t="$TARGET" 'BEGIN {
        r = h > 0 ? i / h : 0
        printf "%-22s %12d %12d %7.2f  %s\n", n, i, h, r, r <= t ? "met" : "not met" }'
done
i=$(per_step mech_solve conveyor interp forces) h=$(per_step hand_sweep conveyor hand forces)
awk -v n="conveyor+forces" -v i="$i" -v h="$h" -v t="$TARGET" 'BEGIN {
    r = h > 0 ? i / h : 0
    printf "%-22s %12d %12d %7.2f  %s\n", n, i, h, r, r <= t ? "met" : "not met" }'
echo "(conveyor+forces: joint reactions and driver torque, friction off; the hand-written"
echo "force solver assembles the 15 x 15 Newton-Euler system densely and factors it by dense LU)"
