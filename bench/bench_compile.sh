#!/bin/sh
# bench/bench_compile.sh: what compiling a mechanism's solver costs (issue
# 33, target 1: at most 0.5 s of CPU for every shipped example) and what a
# cached one costs instead. For each mechanisms/*.yaml (its own range and
# options), three runs of `mech solve -o /dev/null`:
#   interp  --engine interpreted                     the process's CPU
#   cold    --engine compiled, an empty cache        the process's CPU, the
#           compiler's included (/usr/bin/time counts waited-for children)
#   warm    --engine compiled, the same cache again  --stats's set-up (wall)
# compile CPU = cold - interp (the source's generation, the compiler and the
# loading; the sweep is short and the same in both). A file the generated
# code does not take (a note, the interpreter solves) shows "-".
# Not a test: prints a table. Run from the repository root:
#   MECH=build/mech sh bench/bench_compile.sh
MECH=${MECH:-build/mech}
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
export MECH_CACHE_DIR="$tmp/cache"
[ -x /usr/bin/time ] || { echo "bench_compile: /usr/bin/time is not installed: no CPU figures"; exit 0; }

cpu() {  # cpu ENGINE FILE: "user+sys" CPU seconds of the run; its stderr in $tmp/err
    /usr/bin/time -f "cpu %U %S" "$MECH" solve "$2" --engine "$1" --stats -q -o /dev/null \
        2>"$tmp/err" >/dev/null || return 1
    awk '/^cpu / { printf "%.3f\n", $2 + $3 }' "$tmp/err"
}

echo "compiling a mechanism's solver (issue 33, target 1: <= 0.5 s CPU): CPU seconds of"
echo "mech solve interpreted and compiled with an empty cache (the difference: the compile),"
echo "and the set-up of a second compiled run, from the cache"
printf '%-28s %9s %9s %11s %13s %s\n' mechanism "interp s" "cold s" "compile s" "cache hit s" target
met=0 total=0
for f in mechanisms/*.yaml; do
    name=$(basename "$f" .yaml)
    rm -rf "$MECH_CACHE_DIR"
    a=$(cpu interpreted "$f") || { printf '%-28s solve failed\n' "$name"; continue; }
    b=$(cpu compiled "$f") || { printf '%-28s solve failed\n' "$name"; continue; }
    if ! grep -q 'solver *compiled' "$tmp/err"; then
        printf '%-28s %9s %9s %11s %13s %s\n' "$name" "$a" - - - \
            "not compiled: $(sed -n 's/.*solver *//p' "$tmp/err" | cut -c1-60)"
        continue
    fi
    "$MECH" solve "$f" --engine compiled --stats -q -o /dev/null 2>"$tmp/err" >/dev/null
    hit=$(awk '/solver .*from the cache/ { c = 1 } / set-up / { sub(/.*set-up /, ""); s = $1 + 0 }
               END { if (c) printf "%.4f", s; else printf "-" }' "$tmp/err")
    total=$((total + 1))
    verdict=$(awk -v a="$a" -v b="$b" 'BEGIN { c = b - a; print (c <= 0.5 ? "met" : "no") }')
    [ "$verdict" = met ] && met=$((met + 1))
    awk -v n="$name" -v a="$a" -v b="$b" -v h="$hit" -v v="$verdict" \
        'BEGIN { printf "%-28s %9.3f %9.3f %11.3f %13s %s\n", n, a, b, b - a, h, v }'
done
echo "target 1 (compile <= 0.5 s CPU): met on $met of $total compiled examples; the cause where"
echo "not: the straight-line code and the unrolled block kernels of one source per mechanism"
echo "(gcc -O2; docs/codegen.md, 'Compile time, what was tried')"

# A sweep's variants share one compiled solver (target 1: "every variant of
# a sweep ... compile at most once"): 200 variants of the conveyor with
# forces (two lengths, leaves of the solver), one thread, the compiler's runs
# counted through a $CC that logs them; CPU of the sweep interpreted, then
# compiled with an empty cache, then again from the cache.
sweep_cpu() {  # sweep_cpu ENGINE OUT: CPU seconds; the messages in $tmp/err
    /usr/bin/time -f "cpu %U %S" "$MECH" sweep mechanisms/conveyor.yaml --vary l1=55mm:65mm:20 \
        --vary l4=435mm:445mm:10 --forces --metric maxabs:driver.torque -j 1 --engine "$1" \
        -o "$2" 2>"$tmp/err" >/dev/null || return 1
    awk '/^cpu / { printf "%.3f\n", $2 + $3 }' "$tmp/err"
}
printf '#!/bin/sh\necho run >>"%s/cc.log"\nexec %s "$@"\n' "$tmp" "${CC:-cc}" >"$tmp/cc-log"
chmod +x "$tmp/cc-log"
rm -rf "$MECH_CACHE_DIR" "$tmp/cc.log"
si=$(sweep_cpu interpreted "$tmp/si.csv")
sc=$(CC=$tmp/cc-log sweep_cpu compiled "$tmp/sc.csv")
sw=$(CC=$tmp/cc-log sweep_cpu compiled "$tmp/sw.csv")
runs=$(wc -l <"$tmp/cc.log" 2>/dev/null || echo 0)
same=no
cmp -s "$tmp/si.csv" "$tmp/sc.csv" && cmp -s "$tmp/si.csv" "$tmp/sw.csv" && same=yes
echo
echo "a sweep of 200 conveyor variants with forces (72 200 rows, one thread): CPU seconds"
printf '%-14s %-14s %-14s %-16s %s\n' interpreted "compiled cold" "compiled warm" "compiler runs" "summaries identical"
printf '%-14s %-14s %-14s %-16s %s\n' "${si:--}" "${sc:--}" "${sw:--}" "$runs" "$same"
[ "$runs" = 1 ] && [ "$same" = yes ] && verdict=met || verdict="not met"
echo "target 1 (a sweep's variants compile at most once, in two sweeps of one structure): $verdict"
