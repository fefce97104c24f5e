#!/bin/sh
# bench/bench_batch.sh: throughput of `mech batch` (mechanism files per
# second) and `mech sweep` (variants per second) against the number of
# workers. Wall time of whole runs, best of 3; not a test.
#   MECH=build/bench/mech sh bench/bench_batch.sh
MECH=${MECH:-build/mech}
files=""
for i in 1 2 3 4 5 6 7 8 9 10; do files="$files $(ls mechanisms/*.yaml | tr '\n' ' ')"; done
nfiles=$(echo $files | wc -w)
ncpu=$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)
best() {  # best of 3 wall times of the command, in seconds
    b=""
    for r in 1 2 3; do
        t0=$(date +%s.%N)
        "$@" >/dev/null 2>&1
        t1=$(date +%s.%N)
        t=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.4f", b - a }')
        if [ -z "$b" ] || awk -v t="$t" -v b="$b" 'BEGIN { exit !(t < b) }'; then b=$t; fi
    done
    echo "$b"
}
echo "throughput against workers ($ncpu processors; best of 3 runs)"
printf "%-8s %8s %14s %10s %16s\n" workers "batch s" "files/s" "sweep s" "variants/s"
for j in 1 2 4 8; do
    tb=$(best "$MECH" batch -q -j $j $files)
    ts=$(best "$MECH" sweep mechanisms/slider-crank.yaml --vary r=20mm:60mm:20 --vary l=100mm:200mm:10 \
        --metric range:x_B.s -j $j)
    awk -v j=$j -v tb="$tb" -v ts="$ts" -v n=$nfiles \
        'BEGIN { printf "%-8s %8.3f %14.1f %10.3f %16.1f\n", j, tb, n / tb, ts, 200 / ts }' 
done
