#!/bin/sh
# bench/bench_merge.sh: `mech merge`'s time and peak memory (GNU time's
# maximum resident set) against the rows: made-up sweep shards of 10^6 and
# 10^7 rows (bench/merge_shards.c) merged; the memory must not grow with
# the rows (docs/batch.md, "What merge proves"). Needs about 1.5 GB in
# $TMPDIR for 10^7 rows; not a test.
#   MECH=build/mech sh bench/bench_merge.sh [ROWS...]
MECH=${MECH:-build/mech}
BUILD=${BUILD:-build}
dir=${TMPDIR:-/tmp}/mech-bench-merge.$$
mkdir -p "$dir" || exit 2
trap 'rm -rf "$dir"' EXIT INT TERM
cc -O2 $(for d in src/*/; do printf -- "-I%s " "${d%/}"; done) -Iinclude $(pkg-config --cflags yaml-0.1 2>/dev/null) -I/usr/include/suitesparse -o "$dir/merge_shards" bench/merge_shards.c "$BUILD/obj/cmd_manifest.o" || exit 2
version=$("$MECH" --version | awk '{ print $2 }')
printf "%-10s %6s %10s %10s %12s %10s\n" rows shards "shards MB" "wall s" "user+sys s" "peak MB"
for rows in ${*:-1000000 10000000}; do
    b=$((rows / 1000)) m=8
    [ "$rows" -ge 10000000 ] && m=32
    rm -f "$dir"/s.*.csv "$dir/out.csv"
    "$dir/merge_shards" "$dir" $m 1000 $b "$version" || exit 3
    mb=$(du -sm "$dir" | awk '{ print $1 }')
    /usr/bin/time -f "%e %U %S %M" -o "$dir/time" "$MECH" merge -o "$dir/out.csv" "$dir"/s.*.csv || exit 3
    [ "$(wc -l <"$dir/out.csv")" -eq $((rows + 1)) ] || { echo "merge: wrong row count"; exit 3; }
    read -r wall user sys kb <"$dir/time"
    awk -v r=$rows -v m=$m -v mb="$mb" -v w="$wall" -v u="$user" -v s="$sys" -v k="$kb" \
        'BEGIN { printf "%-10d %6d %10d %10.2f %12.2f %10.1f\n", r, m, mb, w, u + s, k / 1024 }'
done
