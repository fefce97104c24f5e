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

# Per CPU-second (user + system: what a scheduler's allocation pays for) and
# peak memory (maximum resident set, GNU time's %M), default -j. The sweep's
# memory per variant is the slope between two grid sizes: it must stay near
# the output's own bytes per row (rows are streamed to OUT.partial, then put
# in order with 8 bytes per variant; docs/batch.md).
TIME=/usr/bin/time
if [ ! -x $TIME ]; then
    echo "(GNU time not installed: no CPU-second and memory table; Debian package time)"
    exit 0
fi
tmp=${TMPDIR:-/tmp}/mech-bench-batch.$$
mkdir "$tmp" || exit 2
trap 'rm -rf "$tmp"' EXIT
measure() {  # measure LABEL ITEMS COMMAND...: one row of the table
    label=$1 items=$2
    shift 2
    $TIME -f "%e %U %S %M" -o "$tmp/time" "$@" >/dev/null 2>&1
    # the last line: GNU time writes "Command exited with non-zero status" first
    set -- $(tail -n 1 "$tmp/time")
    wall=$1 user=$2 sys=$3 kb=$4
    awk -v l="$label" -v n="$items" -v w="$wall" -v u="$user" -v s="$sys" -v k="$kb" \
        'BEGIN { c = u + s; if (c < 0.01) c = 0.01
                 printf "%-34s %8d %8.2f %8.2f %12.1f %9.1f\n", l, n, w, c, n / c, k / 1024 }'
    echo "$kb" >"$tmp/kb"
}
echo
echo "throughput per CPU-second and peak memory (default -j: $ncpu)"
printf "%-34s %8s %8s %8s %12s %9s\n" run items "wall s" "cpu s" "items/cpu-s" "peak MB"
conv="mechanisms/conveyor.yaml --metric range:E.x --metric maxabs:driver.torque --forces"
measure "sweep conveyor (variants)" 2000 "$MECH" sweep $conv -q \
    --vary l1=50mm:64mm:100 --vary l2=420mm:440mm:20 -o "$tmp/c.csv"
measure "sweep slider-crank (variants)" 2000 "$MECH" sweep mechanisms/slider-crank.yaml -q \
    --vary r=20mm:60mm:100 --vary l=100mm:200mm:20 --metric range:x_B.s -o "$tmp/s.csv"
measure "batch mechanisms/*.yaml x10 (files)" "$nfiles" "$MECH" batch -q $files
measure "sweep conveyor, 1000 variants" 1000 "$MECH" sweep $conv -q \
    --vary l1=50mm:64mm:50 --vary l2=420mm:440mm:20 -o "$tmp/m1.csv"
kb1=$(cat "$tmp/kb")
measure "sweep conveyor, 8000 variants" 8000 "$MECH" sweep $conv -q \
    --vary l1=50mm:64mm:400 --vary l2=420mm:440mm:20 -o "$tmp/m2.csv"
kb2=$(cat "$tmp/kb")
row=$(awk 'NR > 1 { n += length($0) + 1 } END { printf "%.0f", n / (NR - 1) }' "$tmp/m2.csv")
awk -v a="$kb1" -v b="$kb2" -v r="$row" 'BEGIN {
    printf "sweep memory per variant: %.0f bytes (peak %.1f MB at 1000, %.1f MB at 8000 variants; a row of the output is %d bytes)\n",
        (b - a) * 1024 / 7000, a / 1024, b / 1024, r }'

# A batch's memory per file, the same way: 1000 and 16000 invalid files
# (a parse error each: about 250 bytes of messages, no solve). The messages
# are printed as each file finishes, so the slope is the per-file state kept
# for the table in list order (its job: name, status, numbers), not the
# messages.
bad=tests/bad/01-bad-indentation.yaml
yes $bad | head -n 1000 >"$tmp/bad1"
yes $bad | head -n 16000 >"$tmp/bad2"
measure "batch, 1000 invalid files" 1000 "$MECH" batch -j 1 --files-from "$tmp/bad1" -o "$tmp/b1.txt"
kb1=$(cat "$tmp/kb")
measure "batch, 16000 invalid files" 16000 "$MECH" batch -j 1 --files-from "$tmp/bad2" -o "$tmp/b2.txt"
kb2=$(cat "$tmp/kb")
msg=$("$MECH" batch -j 1 $bad 2>&1 >/dev/null | wc -c)
row=$(awk 'NR > 1 { n += length($0) + 1 } END { printf "%.0f", n / (NR - 1) }' "$tmp/b2.txt")
awk -v a="$kb1" -v b="$kb2" -v m="$msg" -v r="$row" 'BEGIN {
    printf "batch memory per file: %.0f bytes (peak %.1f MB at 1000, %.1f MB at 16000 files; a file'"'"'s messages are %d bytes, its row of the table %d)\n",
        (b - a) * 1024 / 15000, a / 1024, b / 1024, m, r }'
