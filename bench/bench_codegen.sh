#!/bin/sh
# bench/bench_codegen.sh: the generated code (`mech codegen`) against the
# solvers written by hand for one mechanism (bench/bench_hand.c) and the
# interpreter, in instructions per driver step counted by callgrind (no
# noise), and the generated code's time per step. Positions, velocities and
# accelerations of the same outputs, the file's 361 steps, tolerance 1e-12.
#
#   hand: bench-hand under callgrind, one profile per table row
#         (--dump-after=row): the row's instructions less the interpreter's
#         (mech_solve, mech_table_free), over its 31 sweeps
#   interp: mech_solve's instructions in the same profile, per step (set-up
#         included: the analysis is built by each call)
#   gen:  bench/bench_codegen.c under callgrind, one sweep (bench_sweep)
# Target (issue 21): gen / hand <= 1.2. Not a test: prints a table.
# Run from the repository root after building BUILD/mech and BUILD/bench-hand:
#   MECH=build/bench/mech BUILD=build/bench sh bench/bench_codegen.sh
MECH=${MECH:-build/bench/mech}
BUILD=${BUILD:-build/bench}
CC=${CC:-cc}
out=$BUILD/codegen
mkdir -p "$out" || exit 2
reps=31
steps=361

echo "generated code (mech codegen) against the hand-written solvers: instructions per"
echo "driver step (callgrind), positions + velocities + accelerations, tol 1e-12;"
echo "ratio = generated / hand-written (target <= 1.2); us/step: the generated code's"
echo "median (and min) of 31 sweeps"
if ! command -v valgrind >/dev/null; then
    echo "  (valgrind is not installed: no instruction counts)"
else
    rm -f "$out"/hand.out*
    valgrind --tool=callgrind --toggle-collect=row --dump-after=row \
        --callgrind-out-file="$out/hand.out" "$BUILD/bench-hand" mechanisms >/dev/null 2>"$out/hand.err" \
        || { echo "bench-hand under callgrind failed: $(tail -n 3 "$out/hand.err")"; exit 1; }
fi

# inclusive FILE FUNCTION: the inclusive instruction count of FUNCTION in a profile
inclusive() {
    callgrind_annotate --inclusive=yes "$1" 2>/dev/null |
        awk -v f="$2" '$3 ~ ("^[^ ]*:" f "$") { gsub(",", "", $1); s += $1 } END { print s + 0 }'
}

printf "%-10s %9s %9s %9s %7s %9s %9s %8s\n" mechanism interp hand generated ratio "us/step" "(min)" "it/step"
dump=1
for m in fourbar stirling conveyor; do
    gen=$out/$m
    mkdir -p "$gen"
    if ! "$MECH" codegen "mechanisms/$m.yaml" -o "$gen/gen.c" --header "$gen/gen.h" --prefix gen ||
       ! $CC -std=c11 -Wall -Wextra -Werror -O2 -DNDEBUG -I"$gen" -o "$gen/bench" "$gen/gen.c" bench/bench_codegen.c -lm; then
        echo "$m: cannot generate or compile"
        exit 1
    fi
    timing=$("$gen/bench") || { echo "$m: the generated solver failed"; exit 1; }
    set -- $timing  # steps S us/step M (min N) iterations/step I
    us=$4 usmin=${6%)} it=$8
    interp=- hand=- gen_i=- ratio=-
    if command -v valgrind >/dev/null; then
        prof=$out/hand.out.$dump
        total=$(grep '^totals:' "$prof" | awk '{ print $2 }')
        solve=$(inclusive "$prof" mech_solve)
        tfree=$(inclusive "$prof" mech_table_free)
        hand=$(( (total - solve - tfree) / (reps * steps) ))
        interp=$(( solve / (reps * steps) ))
        rm -f "$gen/cg.out"
        valgrind --tool=callgrind --toggle-collect="bench_sweep*" --callgrind-out-file="$gen/cg.out" \
            "$gen/bench" --once >/dev/null 2>&1
        gen_i=$(( $(grep '^totals:' "$gen/cg.out" | awk '{ print $2 }') / steps ))
        ratio=$(awk -v g="$gen_i" -v h="$hand" 'BEGIN { printf "%.2f", g / h }')
    fi
    printf "%-10s %9s %9s %9s %7s %9s %9s %8s\n" "$m" "$interp" "$hand" "$gen_i" "$ratio" "$us" "$usmin" "$it"
    dump=$((dump + 2))  # bench-hand: each mechanism at tol 1e-12, then 1e-15
done
