#!/bin/sh
# tests/sweep.sh: a sweep of 10 000 conveyor variants (100 under a sanitizer,
# MECH_SANITIZE=1) completes, and its summary rows agree with solving a few
# variants alone (`mech solve --set`); then the distributed recipe: shards
# run as separate local processes in parallel (xargs -P, and GNU Parallel
# when installed) and merged, equal to the unsharded run.
# Run from the repository root:  MECH=build/mech sh tests/sweep.sh
NAME=sweep . tests/lib.sh

n=100
[ -n "$MECH_SANITIZE" ] && n=10
total=$((n * n))
file=mechanisms/conveyor.yaml
metrics="--metric range:E.x --metric maxabs:driver.torque"
if "$MECH" sweep $file --vary l1=50mm:64mm:$n --vary l2=420mm:440mm:$n $metrics \
        -o "$tmp/all.csv" 2>"$tmp/err"; then
    rows=$(($(wc -l <"$tmp/all.csv") - 1))
    head -n 1 "$tmp/all.csv" | grep -q '^variant \[-\],l1 \[m\],l2 \[m\],status \[-\],rows \[-\],range:E.x \[m\],maxabs:driver.torque \[N\*m\]$' \
        && pass || fail "sweep header: $(head -n 1 "$tmp/all.csv")"
    [ "$rows" -eq "$total" ] && pass || fail "sweep: $rows rows, expected $total"
    ok=$(grep -c ',ok,361,' "$tmp/all.csv")
    [ "$ok" -eq "$total" ] && pass || fail "sweep: $ok of $total variants ok"
else
    fail "mech sweep of $total conveyor variants: $(head -n 3 "$tmp/err")"
fi

# column NAME of a solve's CSV: its index (1-based), from the header
column() { head -n 1 "$1" | tr ',' '\n' | grep -n "^$2 \[" | cut -d: -f1; }

# a few variants solved alone must give the same summary
for v in 0 $((total / 3)) $((total * 2 / 3 + 7)) $((total - 1)); do
    row=$(grep "^$v," "$tmp/all.csv")
    l1=$(echo "$row" | cut -d, -f2)
    l2=$(echo "$row" | cut -d, -f3)
    # the sweep writes SI values (the header says m): give them with their unit
    if ! "$MECH" solve $file --set "l1=${l1}m" --set "l2=${l2}m" -o "$tmp/one.csv" 2>"$tmp/err"; then
        fail "mech solve --set l1=${l1}m --set l2=${l2}m: $(head -n 1 "$tmp/err")"
        continue
    fi
    ex=$(column "$tmp/one.csv" E.x)
    tq=$(column "$tmp/one.csv" driver.torque)
    alone=$(awk -F, -v e="$ex" -v t="$tq" 'NR > 1 {
            if (NR == 2 || $e < lo) lo = $e; if (NR == 2 || $e > hi) hi = $e
            a = $t < 0 ? -$t : $t; if (a > big) big = a }
        END { printf "%.17g %.17g", hi - lo, big }' "$tmp/one.csv")
    swept=$(echo "$row" | awk -F, '{ printf "%.17g %.17g", $6, $7 }')
    if echo "$alone $swept" | awk '{ exit !(($1 - $3)^2 <= (1e-12 * $1)^2 && ($2 - $4)^2 <= (1e-12 * $2)^2) }'; then
        pass
    else
        fail "variant $v (l1=$l1, l2=$l2): sweep says $swept, solving it alone gives $alone"
    fi
done

# the distributed recipe with local workers: M shards as separate processes
m=3
sub="--vary l1=50mm:64mm:6 --vary l2=420mm:440mm:5"
"$MECH" sweep $file $sub $metrics -j 1 -o "$tmp/ref.csv" 2>/dev/null
seq 0 $((m - 1)) | xargs -P $m -I K "$MECH" sweep $file $sub $metrics -j 1 --shard K/$m \
    -o "$tmp/shard.K.csv" 2>/dev/null
{ head -n 1 "$tmp/shard.0.csv"; tail -q -n +2 "$tmp"/shard.*.csv | sort -t, -k1,1n; } >"$tmp/merged.csv"
cmp -s "$tmp/merged.csv" "$tmp/ref.csv" && pass || fail "xargs -P $m shards merged differ from the single run"
if command -v parallel >/dev/null 2>&1; then
    seq 0 $((m - 1)) | parallel -j $m "$MECH sweep $file $sub $metrics -j 1 --shard {}/$m -o $tmp/par.{}.csv" 2>/dev/null
    { head -n 1 "$tmp/par.0.csv"; tail -q -n +2 "$tmp"/par.*.csv | sort -t, -k1,1n; } >"$tmp/pmerged.csv"
    cmp -s "$tmp/pmerged.csv" "$tmp/ref.csv" && pass || fail "GNU Parallel shards merged differ from the single run"
fi
# batch shards: every file in exactly one shard, same CSVs as one batch
mkdir "$tmp/b1" "$tmp/b2"
"$MECH" batch -q --out-dir "$tmp/b1" mechanisms/*.yaml >/dev/null 2>&1
seq 0 $((m - 1)) | xargs -P $m -I K "$MECH" batch -q -j 1 --shard K/$m --out-dir "$tmp/b2" \
    mechanisms/*.yaml >/dev/null 2>&1
diff -r "$tmp/b1" "$tmp/b2" >/dev/null && pass || fail "batch shards differ from one batch"

summary
