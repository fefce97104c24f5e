#!/bin/sh
# bench/bench_fit_paths.sh: mech fit on four-bar path synthesis as the
# literature poses it (docs/synthesis.md, "Path synthesis with every
# dimension free"): nine design variables (ground pivot, ground link and its
# angle, crank, coupler, coupler point, rocker) within bounds, the timing
# free, a Grashof crank-rocker as three constraints. Each problem is run
# from several seeds (--seed: the Halton starts shifted at random), and the
# table gives per seed the objective, the solves and the time, then the
# best, the median and the success rate (the runs within 1 % of the best
# objective over all seeds, or below 1e-20 when an exact solution exists).
#   MECH=build/mech sh bench/bench_fit_paths.sh [SEEDS [STARTS]]
MECH=${MECH:-build/mech}
SEEDS=${1:-5}
STARTS=${2:-40}
D=bench/fit
tmp=${TMPDIR:-/tmp}/mech-bench-fitpaths.$$
mkdir "$tmp" || exit 2
trap 'rm -rf "$tmp"' EXIT

# run PROBLEM FILE [OPTIONS...]: one line per seed into $tmp/PROBLEM
run() {
    name=$1 file=$2
    shift 2
    : >"$tmp/$name"
    s=1
    while [ "$s" -le "$SEEDS" ]; do
        if "$MECH" fit "$file" --starts "$STARTS" --seed "$s" -j 2 "$@" >"$tmp/out" 2>&1; then
            obj=$(sed -n 's/^objective *\([^ ]*\).*/\1/p' "$tmp/out")
            solves=$(sed -n 's/^solves *\([0-9]*\).*/\1/p' "$tmp/out")
            secs=$(sed -n 's/^time *\([0-9.e+-]*\) s.*/\1/p' "$tmp/out")
        else
            obj=inf solves=- secs=-
        fi
        echo "$s $obj $solves $secs" >>"$tmp/$name"
        s=$((s + 1))
    done
}

# table PROBLEM EXACT: the seeds' lines and the summary
table() {
    echo "$1 ($STARTS starts a seed, 2 threads):"
    printf '  %-5s %14s %8s %8s\n' seed objective solves "time s"
    awk '{ printf "  %-5s %14s %8s %8s\n", $1, $2, $3, $4 }' "$tmp/$1"
    sort -g -k2 "$tmp/$1" | awk -v exact="$2" '
        { o[NR] = $2; if ($3 != "-") { solves += $3; secs += $4; n++ } }
        END {
            best = o[1]; med = (NR % 2) ? o[(NR + 1) / 2] : (o[NR / 2] + o[NR / 2 + 1]) / 2
            for (i = 1; i <= NR; i++) ok += exact ? (o[i] < 1e-20) : (o[i] <= 1.01 * best)
            printf "  best %.6g, median %.6g, success %d of %d (%s), %.0f solves and %.3g s a seed\n",
                   best, med, ok, NR, exact ? "objective below 1e-20" : "within 1 % of the best",
                   n ? solves / n : 0, n ? secs / n : 0 }'
}

# 1. The 18 points of Kunjur and Krishnamurty (1997), a closed curve, the
#    start angles 0, 20, ..., 340 deg in the points' order.
run kunjur18 $D/fourbar-path.yaml
table kunjur18 0

# 2. An open path of 60 points that a known crank-rocker traces (so the
#    optimum is exact): its coupler point over 236 deg of crank, the start
#    angles moved by up to 7 deg, the file's dimensions elsewhere.
sed -e 's/^  x0: .*/  x0: 0.1 m/' -e 's/^  y0: .*/  y0: 0.4 m/' -e 's/^  th0: .*/  th0: 10 deg/' \
    -e 's/^  r1: .*/  r1: 1.2 m/' -e 's/^  r2: .*/  r2: 0.35 m/' -e 's/^  r3: .*/  r3: 1.1 m/' \
    -e 's/^  r4: .*/  r4: 0.9 m/' -e 's/^  rcx: .*/  rcx: 0.4 m/' -e 's/^  rcy: .*/  rcy: 0.3 m/' \
    $D/fourbar-path.yaml >"$tmp/true.yaml"
"$MECH" solve "$tmp/true.yaml" --from 0 --to 236 --steps 59 --outputs P --level positions \
    --units file -o "$tmp/all.csv" 2>/dev/null || exit 1
awk -F, 'NR == 1 { print "q [deg],P.x [m],P.y [m]"; next }
         { printf "%.6f,%s,%s\n", $1 + 7 * sin(NR), $2, $3 }' "$tmp/all.csv" >"$tmp/open60.csv"
run open60 $D/fourbar-path.yaml --target "$tmp/open60.csv"
table open60 1
