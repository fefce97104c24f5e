#!/bin/sh
# bench/bench_simulate.sh: work-precision of `mech simulate` (docs/dynamics.md)
# on two examples of tests/dynamics/: for each method and tolerance, the
# largest error of the free coordinate's angle over the run against a tight
# reference (Adams, rtol 1e-13), the integration steps, and the wall time
# per simulated second; then the cost of one evaluation against one
# kinematic row of `mech solve`.
#   MECH=build/mech sh bench/bench_simulate.sh
MECH=${MECH:-build/mech}
tmp=${TMPDIR:-/tmp}/mech-bench-sim.$$
mkdir "$tmp" || exit 2
trap 'rm -rf "$tmp"' EXIT

col() { head -n 1 "$1" | tr ',' '\n' | grep -n "^$2 \[" | cut -d: -f1; }

one() {  # FILE COLUMN TO: the table of one example
    f=$1 c=$2 to=$3
    "$MECH" simulate "$f" --to "$to" --step 0.01 --method adams --rtol 1e-13 --atol 1e-15 -o "$tmp/ref.csv" 2>/dev/null || return 1
    k=$(col "$tmp/ref.csv" "$c")
    echo "simulate $f to $to s, error of $c against Adams rtol 1e-13:"
    printf '  %-6s %-7s %12s %9s %14s\n' method rtol "max error" steps "ms per sim s"
    for m in bdf adams; do
        for r in 1e-6 1e-8 1e-10 1e-12; do
            "$MECH" simulate "$f" --to "$to" --step 0.01 --method $m --rtol $r --atol 1e-14 --stats -o "$tmp/run.csv" 2>"$tmp/err" || continue
            e=$(paste -d, "$tmp/run.csv" "$tmp/ref.csv" | awk -F, -v k="$k" -v n="$(head -n 1 "$tmp/run.csv" | tr ',' '\n' | wc -l)" \
                'NR > 1 { d = $k - $(n + k); if (d < 0) d = -d; if (d > w) w = d } END { printf "%.3g", w + 0 }')
            steps=$(sed -n 's/.*atol [^:]*: \([0-9]*\) steps.*/\1/p' "$tmp/err")
            secs=$(sed -n 's/^  time *\([0-9.e+-]*\) s .*/\1/p' "$tmp/err")
            printf '  %-6s %-7s %12s %9s %14.3g\n' $m $r "$e" "$steps" "$(awk -v s="$secs" -v t="$to" 'BEGIN { print 1000 * s / t }')"
        done
    done
    per=$(sed -n 's/.*(\([0-9.e+-]*\) us per state).*/\1/p' "$tmp/err")
    "$MECH" solve "$f" --forces --stats -o /dev/null 2>"$tmp/kin"
    kin=$(sed -n 's/^  time *\([0-9.e+-]*\) us per step.*/\1/p' "$tmp/kin")
    echo "  one evaluation $per us (positions, rates, mass matrix, forces); one kinematic row with forces of mech solve $kin us"
}
one tests/dynamics/pendulum.yaml bar.angle 5
one mechanisms/dynamics/pendulum-fourbar.yaml crank.angle 2
