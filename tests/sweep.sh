#!/bin/sh
# tests/sweep.sh: a sweep of 10 000 conveyor variants (100 under a sanitizer,
# MECH_SANITIZE=1) completes, and its summary rows agree with solving a few
# variants alone (`mech solve --set`), as every variant of a four-bar's
# sweep does (one analysis per sweep: variant_regs.c); then the distributed recipe: shards
# run as separate local processes in parallel (xargs -P, and GNU Parallel
# when installed) and merged, equal to the unsharded run. MECH_QUICK=1: the
# sizes of a sanitizer's sweep, and fewer variants and files in the later
# checks (the same checks).
# Run from the repository root:  MECH=build/mech sh tests/sweep.sh
NAME=sweep . tests/lib.sh

n=100 side=30 copies=200  # the sweep's n x n; the resumed grid's side; the batch's files
[ -n "$MECH_SANITIZE" ] && n=10
[ -n "$MECH_QUICK" ] && n=10 side=12 copies=20
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

# a four-bar (the double crank, its dimensions as parameters): every variant
# of a 3 x 3 sweep, solved through the sweep's one analysis, against solving
# it alone with --set (range and largest of a position, a velocity and an
# acceleration), to 1e-12 relative
fb=mechanisms/double-crank.yaml
fbm="--metric range:B.x --metric max:B.vy --metric maxabs:P.ax"
if "$MECH" sweep $fb --vary l1=58mm:62mm:3 --vary l3=69mm:71mm:3 $fbm -o "$tmp/fb.csv" 2>"$tmp/err"; then
    has_line "$tmp/err" "^mech sweep: 9 variants solved through the sweep's one analysis, 0 analysed on their own$" \
        "double crank: every variant through the one analysis"
    for v in 0 1 2 3 4 5 6 7 8; do
        row=$(grep "^$v," "$tmp/fb.csv")
        l1=$(echo "$row" | cut -d, -f2)
        l3=$(echo "$row" | cut -d, -f3)
        if ! "$MECH" solve $fb --set "l1=${l1}m" --set "l3=${l3}m" -o "$tmp/one.csv" 2>"$tmp/err"; then
            fail "double crank, mech solve --set l1=${l1}m --set l3=${l3}m: $(head -n 1 "$tmp/err")"
            continue
        fi
        bx=$(column "$tmp/one.csv" B.x)
        bvy=$(column "$tmp/one.csv" B.vy)
        pax=$(column "$tmp/one.csv" P.ax)
        alone=$(awk -F, -v e="$bx" -v w="$bvy" -v a="$pax" 'NR > 1 {
                if (NR == 2 || $e < lo) lo = $e; if (NR == 2 || $e > hi) hi = $e
                if (NR == 2 || $w > wmax) wmax = $w
                x = $a < 0 ? -$a : $a; if (x > big) big = x }
            END { printf "%.17g %.17g %.17g", hi - lo, wmax, big }' "$tmp/one.csv")
        swept=$(echo "$row" | awk -F, '{ printf "%.17g %.17g %.17g", $6, $7, $8 }')
        if echo "$alone $swept" | awk '{ exit !(($1 - $4)^2 <= (1e-12 * $1)^2 && ($2 - $5)^2 <= (1e-12 * $2)^2 && ($3 - $6)^2 <= (1e-12 * $3)^2) }'; then
            pass
        else
            fail "double crank variant $v (l1=$l1, l3=$l3): sweep says $swept, solving it alone gives $alone"
        fi
    done
else
    fail "mech sweep of 9 double-crank variants: $(head -n 3 "$tmp/err")"
fi

# the distributed recipe with local workers: M shards as separate
# processes, joined by mech merge (which checks their manifests)
m=3
sub="--vary l1=50mm:64mm:6 --vary l2=420mm:440mm:5"
"$MECH" sweep $file $sub $metrics -j 1 -o "$tmp/ref.csv" 2>/dev/null
head -n 1 "$tmp/ref.csv" | grep -q '^variant ' && pass || fail "an unsharded sweep starts with a manifest"
seq 0 $((m - 1)) | xargs -P $m -I K "$MECH" sweep $file $sub $metrics -j 1 --shard K/$m \
    -o "$tmp/shard.K.csv" 2>/dev/null
has_line "$tmp/shard.1.csv" '^# mech-manifest version=[0-9.]* command=sweep shard=1/3 rows=10 total=30 offset=0 ' "the manifest of shard 1/3"
if run "mech merge" 0 "$MECH" merge -o "$tmp/merged.csv" "$tmp"/shard.*.csv; then
    cmp -s "$tmp/merged.csv" "$tmp/ref.csv" && pass || fail "xargs -P $m shards merged differ from the single run"
fi
if command -v parallel >/dev/null 2>&1; then
    seq 0 $((m - 1)) | parallel -j $m "$MECH sweep $file $sub $metrics -j 1 --shard {}/$m -o $tmp/par.{}.csv" 2>/dev/null
    "$MECH" merge -o "$tmp/pmerged.csv" "$tmp"/par.*.csv
    cmp -s "$tmp/pmerged.csv" "$tmp/ref.csv" && pass || fail "GNU Parallel shards merged differ from the single run"
fi

# merge refuses what is not one whole run, names the shard, writes nothing
merge_refused() {  # LABEL PATTERN SHARD...
    label=$1 pattern=$2
    shift 2
    if run "$label" 2 "$MECH" merge -o "$tmp/bad.csv" "$@"; then
        has_line "$tmp/err" "$pattern" "merge, $label"
        [ ! -e "$tmp/bad.csv" ] && pass || fail "merge, $label: a file was written"
    fi
}
merge_refused "a shard missing" '^mech merge: shard 1/3 missing$' "$tmp/shard.0.csv" "$tmp/shard.2.csv"
merge_refused "a shard twice" '^mech merge: shard 2/3 given twice' "$tmp"/shard.*.csv "$tmp/shard.2.csv"
head -n 5 "$tmp/shard.1.csv" >"$tmp/cut.csv"
merge_refused "a shard cut off" '^mech merge: shard 1/3 unfinished: 3 of 10 rows (.*cut.csv)$' "$tmp/shard.0.csv" "$tmp/cut.csv" "$tmp/shard.2.csv"
printf '1,0.05' >>"$tmp/cut.csv"  # a row cut by a kill is no row
merge_refused "a shard cut in a row" 'shard 1/3 unfinished: 3 of 10 rows' "$tmp/shard.0.csv" "$tmp/cut.csv" "$tmp/shard.2.csv"
mv "$tmp/cut.csv" "$tmp/gone.csv.partial"  # only the partial file of a killed run
merge_refused "only OUT.partial" 'shard 1/3 unfinished: 3 of 10 rows (.*gone.csv.partial)$' "$tmp/shard.0.csv" "$tmp/gone.csv" "$tmp/shard.2.csv"
sed '$d' "$tmp/shard.1.csv" >"$tmp/short.csv"  # its last row twice, then its digest line
tail -n 2 "$tmp/shard.1.csv" | head -n 1 >>"$tmp/short.csv"; tail -n 1 "$tmp/shard.1.csv" >>"$tmp/short.csv"
merge_refused "a shard with a row too many" 'shard 1/3 (.*short.csv): 11 rows, its manifest says 10 (edited)' "$tmp/shard.0.csv" "$tmp/short.csv" "$tmp/shard.2.csv"
"$MECH" sweep $file --vary l1=50mm:64mm:6 --vary l2=420mm:440mm:6 $metrics -j 1 --shard 1/3 -o "$tmp/grid.csv" 2>/dev/null
merge_refused "another grid" 'shard 1/3 (.*grid.csv) is not from the same run as shard 0/3 (.*): its grid differs' "$tmp/shard.0.csv" "$tmp/grid.csv" "$tmp/shard.2.csv"
"$MECH" sweep $file $sub $metrics -j 1 --shard 1/4 -o "$tmp/m4.csv" 2>/dev/null
merge_refused "another M" 'splits the run in 3 shards, shard 1/4 (.*m4.csv) in 4' "$tmp/shard.0.csv" "$tmp/m4.csv" "$tmp/shard.2.csv"
sed 's/^4,/7,/' "$tmp/shard.1.csv" >"$tmp/dup.csv"
merge_refused "an index twice" "row 2 (line 4): index 7 where this shard's row 2 has 4" "$tmp/shard.0.csv" "$tmp/dup.csv" "$tmp/shard.2.csv"
sed '2s/E.x/E.y/' "$tmp/shard.1.csv" >"$tmp/head.csv"
merge_refused "another header" 'its header differs' "$tmp/shard.0.csv" "$tmp/head.csv" "$tmp/shard.2.csv"
merge_refused "no manifest" "ref.csv: no '# mech-manifest' line" "$tmp/ref.csv"
cp $file "$tmp/conv.yaml"
sed -i 's/^# .*//' "$tmp/conv.yaml"
"$MECH" sweep "$tmp/conv.yaml" $sub $metrics -j 1 --shard 1/3 -o "$tmp/other-input.csv" 2>/dev/null
merge_refused "another input file" 'its input file (its contents) differs' "$tmp/shard.0.csv" "$tmp/other-input.csv" "$tmp/shard.2.csv"

# one index space over two grids: --index-offset, merged with the grid
# that covers both (l2 split 420..430 and 435..440)
"$MECH" sweep $file --vary l1=50mm:64mm:6 --list l2=420mm,425mm,430mm $metrics -j 1 --shard 0/1 -o "$tmp/g1.csv" 2>/dev/null
"$MECH" sweep $file --vary l1=50mm:64mm:6 --list l2=435mm,440mm $metrics -j 1 --index-offset 18 -o "$tmp/g2.csv" 2>/dev/null
if run "merge of two grids" 0 "$MECH" merge -o "$tmp/g.csv" "$tmp/g1.csv" "$tmp/g2.csv"; then
    [ "$(wc -l <"$tmp/g.csv")" -eq 31 ] && pass || fail "merge of two grids: $(wc -l <"$tmp/g.csv") lines"
    # the same variants as the one grid, under their new numbers
    cut -d, -f2- "$tmp/g.csv" | sort >"$tmp/g.rows"
    cut -d, -f2- "$tmp/ref.csv" | sort >"$tmp/ref.rows"
    cmp -s "$tmp/g.rows" "$tmp/ref.rows" && pass || fail "merge of two grids: other rows than the one grid"
fi
"$MECH" sweep $file --vary l1=50mm:64mm:6 --list l2=435mm,440mm $metrics -j 1 --index-offset 20 -o "$tmp/g3.csv" 2>/dev/null
merge_refused "a gap in the index space" 'indices 18..19 are in no shard' "$tmp/g1.csv" "$tmp/g3.csv"

# rows as they finish: a killed sweep leaves OUT.partial, --resume ends it
big="--vary l1=50mm:64mm:$side --vary l2=420mm:440mm:$side"
"$MECH" sweep $file $big $metrics -q -o "$tmp/whole.csv" 2>/dev/null
# (rows reach OUT.partial in blocks, at least every second: killed after the first)
"$MECH" sweep $file $big $metrics -q -o "$tmp/res.csv" 2>/dev/null &
pid=$!
for i in $(seq 300); do  # (or until the sweep ends: then the kill test is skipped)
    grep -q '^# mech-block ' "$tmp/res.csv.partial" 2>/dev/null && break
    kill -0 $pid 2>/dev/null || break
    sleep 0.1
done
kill -KILL $pid 2>/dev/null
wait $pid 2>/dev/null
if [ -f "$tmp/res.csv.partial" ] && [ ! -f "$tmp/res.csv" ]; then
    done=$(($(grep -vc '^#' "$tmp/res.csv.partial") - 1))
    blocks=$(grep -c '^# mech-block rows=[0-9]* fnv1a64=[0-9a-f]\{16\}$' "$tmp/res.csv.partial")
    [ "$done" -gt 0 ] && [ "$blocks" -ge 1 ] && pass ||
        fail "a killed sweep kept $done rows in $blocks blocks"
    run "sweep over a partial file without --resume" 2 "$MECH" sweep $file $big $metrics -q -o "$tmp/res.csv" &&
        has_line "$tmp/err" 'res.csv.partial exists' "sweep over a partial file: message"
    run "sweep --resume with another grid" 2 "$MECH" sweep $file --vary l1=50mm:64mm:$((side + 1)) --vary l2=420mm:440mm:$side $metrics -q \
        --resume -o "$tmp/res.csv" && has_line "$tmp/err" 'is not a part of this run' "sweep --resume, another grid: message"
    printf '5,0.05' >>"$tmp/res.csv.partial"  # a row cut by the kill
    if run "sweep --resume" 0 "$MECH" sweep $file $big $metrics -q --resume -o "$tmp/res.csv"; then
        cmp -s "$tmp/res.csv" "$tmp/whole.csv" && pass || fail "sweep --resume: differs from the run never stopped"
        [ ! -e "$tmp/res.csv.partial" ] && pass || fail "sweep --resume: the partial file stays"
    fi
else
    echo "sweep.sh: the sweep finished within 0.5 s, the kill test skipped"
fi

# --unsolvable-ok: no variant solvable is a result (exit 0), not an error
sc=mechanisms/slider-crank.yaml
run "sweep, nothing solvable" 1 "$MECH" sweep $sc --list r=150mm,160mm -q && pass
if run "sweep --unsolvable-ok" 0 "$MECH" sweep $sc --list r=150mm,160mm -q --unsolvable-ok; then
    [ "$(grep -c ',no-assembly,' "$tmp/out")" -eq 2 ] && pass || fail "sweep --unsolvable-ok: rows $(cat "$tmp/out")"
fi
run "sweep --unsolvable-ok, bad input" 2 "$MECH" sweep $sc --list nosuch=1mm -q --unsolvable-ok && pass

# batch shards: every file in exactly one shard, same CSVs as one batch
mkdir "$tmp/b1" "$tmp/b2"
"$MECH" batch -q --out-dir "$tmp/b1" mechanisms/*.yaml >/dev/null 2>&1
seq 0 $((m - 1)) | xargs -P $m -I K "$MECH" batch -q -j 1 --shard K/$m --out-dir "$tmp/b2" \
    mechanisms/*.yaml >/dev/null 2>&1
diff -r "$tmp/b1" "$tmp/b2" >/dev/null && pass || fail "batch shards differ from one batch"

# batch --files-from: a frozen list (a file or standard input), sharded,
# each shard's table with its manifest, merged and checked against the CSVs
ls mechanisms/*.yaml >"$tmp/list"
"$MECH" batch -q -j 1 --files-from "$tmp/list" >"$tmp/sum.txt" 2>/dev/null
"$MECH" batch -q -j 1 mechanisms/*.yaml >"$tmp/sum-args.txt" 2>/dev/null
# the table less its timing column (us/step)
untimed() { awk '{ $5 = ""; print }' "$1"; }
[ "$(untimed "$tmp/sum.txt")" = "$(untimed "$tmp/sum-args.txt")" ] && pass || fail "batch --files-from: another table than the same files as arguments"
for k in 0 1 2; do
    "$MECH" batch -q -j 1 --shard $k/3 --out-dir "$tmp/b3" --files-from - <"$tmp/list" >"$tmp/bsum.$k.txt" 2>/dev/null
done
nfiles=$(wc -l <"$tmp/list")  # shard 1/3 has the files with index % 3 == 1
has_line "$tmp/bsum.1.txt" "^# mech-manifest version=[0-9.]* command=batch shard=1/3 rows=$(( (nfiles + 1) / 3 )) total=$nfiles " "batch shard: manifest"
has_line "$tmp/bsum.1.txt" "^double-crank  *ok .* 1 [0-9a-f]\{16\}\$" "batch shard: rows with their index and CSV hash"
if run "merge batch summaries" 0 "$MECH" merge -o "$tmp/bmerged.txt" "$tmp"/bsum.*.txt; then
    [ "$(untimed "$tmp/bmerged.txt")" = "$(untimed "$tmp/sum.txt")" ] && pass || fail "merged batch summaries differ from one batch's table"
fi
merge_refused "a batch shard missing" '^mech merge: shard 1/3 missing$' "$tmp/bsum.0.txt" "$tmp/bsum.2.txt"
# jansen's index in the list (it moves as mechanisms/ gains files) and its shard
ji=$(( $(grep -n '/jansen\.yaml$' "$tmp/list" | cut -d: -f1) - 1 ))
mv "$tmp/b3/jansen.csv" "$tmp/jansen.csv"
merge_refused "a batch CSV missing" "index $ji (jansen) is ok in its summary, but .*b3/jansen.csv cannot be read" "$tmp"/bsum.*.txt
head -n 5 "$tmp/jansen.csv" >"$tmp/b3/jansen.csv"
merge_refused "a batch CSV cut off" "index $ji (jansen): .*b3/jansen.csv has 4 rows, its summary says" "$tmp"/bsum.*.txt
ls tests/solve/*.yaml | head -n 3 >"$tmp/list2"
"$MECH" batch -q -j 1 --shard 1/3 --out-dir "$tmp/b3" --files-from "$tmp/list2" >"$tmp/sum2.txt" 2>/dev/null
merge_refused "summaries of two lists" 'shard 1/3 (.*sum2.txt) is not from the same run as shard 0/3 .*: its input file (its contents) differs' "$tmp/bsum.0.txt" "$tmp/sum2.txt" "$tmp/bsum.2.txt"
mkdir -p "$tmp/a" "$tmp/b"; cp mechanisms/fourbar.yaml "$tmp/a/m.yaml"
cp mechanisms/slider-crank.yaml "$tmp/b/m.yaml"
printf '%s\n%s\n' "$tmp/a/m.yaml" "$tmp/b/m.yaml" >"$tmp/dups"
if run "batch --files-from, same names" 2 "$MECH" batch -q --shard 0/2 --out-dir "$tmp/bd" --files-from "$tmp/dups"; then
    has_line "$tmp/err" 'a/m.yaml and .*b/m.yaml would both be written to' "batch --files-from, same names: message"
    [ ! -e "$tmp/bd/m.csv" ] && pass || fail "batch --files-from, same names: a CSV was written"
fi
: >"$tmp/empty"
run "batch --files-from an empty list" 2 "$MECH" batch -q --files-from "$tmp/empty" && pass
run "batch --files-from a missing list" 3 "$MECH" batch -q --files-from "$tmp/nosuch" && has_line "$tmp/err" 'cannot read the list' "batch --files-from missing: message"

# batch --skip-existing: a CSV already there is kept (not solved, not written)
echo marker >"$tmp/b3/jansen.csv"
if run "batch --skip-existing" 0 "$MECH" batch -j 1 --shard $((ji % 3))/3 --out-dir "$tmp/b3" --files-from "$tmp/list" --skip-existing; then
    has_line "$tmp/out" "^jansen  *kept .* $ji [0-9a-f]\{16\}\$" "batch --skip-existing: status kept"
    [ "$(cat "$tmp/b3/jansen.csv")" = marker ] && pass || fail "batch --skip-existing: the existing CSV was rewritten"
fi
run "batch --skip-existing without --out-dir" 2 "$MECH" batch --skip-existing mechanisms/fourbar.yaml && pass

# batch -o TABLE: the same table as on standard output, written whole;
# no TABLE.partial left; an input as TABLE refused
if run "batch -o" 0 "$MECH" batch -q -j 1 --files-from "$tmp/list" -o "$tmp/osum.txt"; then
    [ "$(untimed "$tmp/osum.txt")" = "$(untimed "$tmp/sum.txt")" ] && pass || fail "batch -o: another table than on standard output"
    [ ! -s "$tmp/out" ] && pass || fail "batch -o: the table also on standard output"
    [ ! -e "$tmp/osum.txt.partial" ] && pass || fail "batch -o: TABLE.partial stays"
fi
cp "$tmp/list" "$tmp/list.copy"
run "batch -o the list" 2 "$MECH" batch -q --files-from "$tmp/list.copy" -o "$tmp/list.copy" &&
    has_line "$tmp/err" 'the output .*list.copy is the input file' "batch -o the list: message"
cmp -s "$tmp/list" "$tmp/list.copy" && pass || fail "batch -o the list: the list was overwritten"

# a killed batch shard: its rows so far are in TABLE.partial; mech merge
# names it (missing when its TABLE is not given, unfinished when it is);
# rerun with --skip-existing it solves only the rest, and the merge is whole
mkdir "$tmp/many"
for i in $(seq 100 $((99 + copies))); do cp $file "$tmp/many/c$i.yaml"; done
ls "$tmp"/many/*.yaml >"$tmp/mlist"
# (exec: the pid of the background job is mech's, which the kill must reach)
kbatch() { exec "$MECH" batch -j 1 -q --shard "$1"/2 --files-from "$tmp/mlist" --out-dir "$tmp/mcsv" \
    --skip-existing --unsolvable-ok -o "$tmp/msum.$1.txt"; }
(kbatch 0 2>/dev/null)
(kbatch 1 2>/dev/null) &
pid=$!
for i in $(seq 600); do  # until 3 rows are on disk (up to 30 s), or the shard ends
    [ -f "$tmp/msum.1.txt.partial" ] && [ "$(grep -vc '^#' "$tmp/msum.1.txt.partial")" -ge 4 ] && break
    kill -0 $pid 2>/dev/null || break
    sleep 0.05
done
kill -KILL $pid 2>/dev/null
wait $pid 2>/dev/null
if [ ! -e "$tmp/msum.1.txt" ]; then
    kept=$(($(grep -vc '^#' "$tmp/msum.1.txt.partial") - 1))  # (each row has a check line)
    merge_refused "a killed batch shard, not given" '^mech merge: shard 1/2 missing$' "$tmp"/msum.*.txt
    merge_refused "a killed batch shard, given" "^mech merge: shard 1/2 unfinished: $kept of $((copies / 2)) rows (.*msum.1.txt.partial)\$" \
        "$tmp/msum.0.txt" "$tmp/msum.1.txt"
    ncsv=$(ls "$tmp/mcsv" | wc -l)
    # shard 0's CSVs, one per row of shard 1 and at most the one it was
    # killed after writing (its row not yet in TABLE.partial); a shard that
    # had solved every file when killed is no less right
    [ "$ncsv" -ge $((copies / 2 + kept)) ] && [ "$ncsv" -le $((copies / 2 + kept + 1)) ] && pass ||
        fail "a killed batch shard: $ncsv CSVs, $kept rows"
    (kbatch 1 2>"$tmp/err") || fail "the killed batch shard rerun: exit $? ($(head -n 1 "$tmp/err"))"
    if [ -f "$tmp/msum.1.txt" ]; then
        [ "$(grep -c ' kept ' "$tmp/msum.1.txt")" -ge "$kept" ] && pass || fail "the rerun shard solved again what was there"
        [ ! -e "$tmp/msum.1.txt.partial" ] && pass || fail "the rerun shard left its TABLE.partial"
        "$MECH" batch -q -j 1 --files-from "$tmp/mlist" -o "$tmp/mone.txt" 2>/dev/null
        if run "merge after the rerun" 0 "$MECH" merge -o "$tmp/mmerged.txt" "$tmp"/msum.*.txt; then
            # file and status (a kept file's row has no steps nor times)
            [ "$(awk '{ print $1, $2 }' "$tmp/mmerged.txt" | sed 's/ kept$/ ok/')" = "$(awk '{ print $1, $2 }' "$tmp/mone.txt")" ] && pass ||
                fail "merge after the rerun: another table than one batch's"
        fi
    fi
else
    echo "sweep.sh: the batch shard finished before it was killed, the kill test skipped"
fi

# a TABLE.partial that is a link is not written through
ln -s "$tmp/list" "$tmp/linked.txt.partial"
run "batch -o, TABLE.partial a link" 2 "$MECH" batch -q -j 1 mechanisms/fourbar.yaml -o "$tmp/linked.txt" &&
    has_line "$tmp/err" 'linked.txt.partial exists and is not a regular file' "batch -o, TABLE.partial a link: message"
cmp -s "$tmp/list" "$tmp/list.copy" && [ ! -e "$tmp/linked.txt" ] && pass || fail "batch -o, TABLE.partial a link: written"

# a file edited between two shards: the input hash covers the contents
cp "$tmp/many/c100.yaml" "$tmp/c100.orig"
echo "# edited" >>"$tmp/many/c100.yaml"
"$MECH" batch -q -j 1 --shard 1/2 --files-from "$tmp/mlist" --out-dir "$tmp/mcsv" --skip-existing -o "$tmp/edited.txt" 2>/dev/null
merge_refused "a batch file edited between shards" 'shard 1/2 (.*edited.txt) is not from the same run as shard 0/2 .*: its input file (its contents) differs' \
    "$tmp/msum.0.txt" "$tmp/edited.txt"
cp "$tmp/c100.orig" "$tmp/many/c100.yaml"
"$MECH" batch -q -j 1 --shard 1/2 --files-from "$tmp/mlist" -o "$tmp/same.txt" 2>/dev/null
input_of() { head -n 1 "$1" | grep -o ' input=[0-9a-f]*'; }
[ -n "$(input_of "$tmp/same.txt")" ] && [ "$(input_of "$tmp/same.txt")" = "$(input_of "$tmp/msum.0.txt")" ] && pass ||
    fail "batch manifest: the same files, another input hash"

# messages as each file finishes: the first file's (an invalid file) are
# on standard error while the later files are still being solved
sed 's/^links:/links: [/' $file >"$tmp/a-bad.yaml"
first_message() {  # reads the batch's stderr: at its first line, the rows on disk
    IFS= read -r line
    rows=$(($({ grep -v '^#' "$tmp/stream.txt.partial" 2>/dev/null || echo; } | wc -l) - 1))
    echo "$rows ${line%%:*}" >"$tmp/stream.seen"
    cat >/dev/null
}
{ "$MECH" batch -j 1 --unsolvable-ok "$tmp/a-bad.yaml" "$tmp"/many/*.yaml -o "$tmp/stream.txt" 2>&1 >/dev/null; } | first_message
read -r rows who <"$tmp/stream.seen"
[ "$who" = "$tmp/a-bad.yaml" ] && pass || fail "batch messages: the first line is not the bad file's: $who"
[ "$rows" -ge 0 ] && [ "$rows" -lt $((copies / 2)) ] && pass || fail "batch messages: printed only after $rows of $((copies + 1)) files were done"

# batch --unsolvable-ok: a mechanism that cannot be solved is a result
run "batch, an unsolvable file" 1 "$MECH" batch -q mechanisms/fourbar.yaml tests/solve/non-grashof.yaml && pass
if run "batch --unsolvable-ok" 0 "$MECH" batch -q --unsolvable-ok mechanisms/fourbar.yaml tests/solve/non-grashof.yaml; then
    has_line "$tmp/out" '^non-grashof  *FAILED' "batch --unsolvable-ok: the row"
fi
run "batch --unsolvable-ok, an invalid file" 2 "$MECH" batch -q --unsolvable-ok tests/solve/non-grashof.yaml tests/bad/01-bad-indentation.yaml && pass

summary
