#!/bin/sh
# bench/bench_output.sh: does the output keep up with the solver (issue 33,
# target 3)? The four-bar with forces (42 columns) over ROWS rows (default
# 10^6), solved by the interpreter and written as CSV (the shortest text
# that reads back, src/base/fmt.c), as HDF5, and to /dev/null (formatting
# without the disk): the process's CPU seconds (user + system, from
# /usr/bin/time or the shell's times), the solve's own (--stats), the
# rest (writing), rows per second, and the file's size.
# Run from the repository root:  MECH=build/mech sh bench/bench_output.sh
MECH=${MECH:-build/mech}
ROWS=${ROWS:-1000000}
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
steps=$((ROWS - 1))

cpu_of() {  # cpu_of OUT: run mech solve to OUT; print "total_cpu solve_cpu"
    if [ -x /usr/bin/time ]; then
        /usr/bin/time -f "cpu %U %S" "$MECH" solve mechanisms/fourbar.yaml --forces --engine interpreted \
            --steps "$steps" --stats -q -o "$1" 2>"$tmp/err" >/dev/null || return 1
        awk '/^cpu / { u = $2; y = $3 } / time .* per step/ { sub(/.*\(sweep /, ""); s = $1 + 0 }
             END { printf "%.3f %.3f %.3f\n", u, y, s }' "$tmp/err"
    else
        "$MECH" solve mechanisms/fourbar.yaml --forces --engine interpreted --steps "$steps" --stats -q \
            -o "$1" 2>"$tmp/err" >/dev/null || return 1
        awk '/ time .* per step/ { sub(/.*\(sweep /, ""); s = $1 + 0 } END { printf "%.3f %.3f %.3f\n", -1, -1, s }' "$tmp/err"
    fi
}

echo "output against the solve: the four-bar with forces, $ROWS rows of 42 columns,"
echo "interpreted; user, sys = the process's CPU seconds, solve = the sweep's (--stats),"
echo "write = user - solve (set-up included); target: write <= solve. sys is mostly the"
echo "table held whole in memory (ROWS x 42 doubles) and the file's pages"
printf '%-8s %8s %8s %8s %8s %11s %11s %s\n' output "user s" "sys s" "solve s" "write s" "rows/s" "bytes" target
for kind in csv h5 null; do
    out=$tmp/out.$kind
    [ "$kind" = null ] && out=/dev/null
    set -- $(cpu_of "$out") || { echo "$kind: mech solve failed: $(head -n 2 "$tmp/err")"; exit 1; }
    size=$([ -f "$out" ] && wc -c <"$out" || echo -)
    awk -v k="$kind" -v u="$1" -v y="$2" -v s="$3" -v n="$ROWS" -v b="$size" 'BEGIN {
        w = u - s; rate = "-"; if (w > 0) rate = sprintf("%.0f", n / w)
        if (u < 0) printf "%-8s %8s %8s %8.3f %8s %11s %11s %s\n", k, "-", "-", s, "-", "-", b, "(no /usr/bin/time)"
        else printf "%-8s %8.3f %8.3f %8.3f %8.3f %11s %11s %s\n", k, u, y, s, w, rate, b,
                    w <= s ? "met" : "not met" }'
done
