#!/bin/sh
# tests/merge.sh: what `mech merge` proves and what --resume keeps (issue
# 32, points 2-5, 7, 8; docs/batch.md "What merge proves"): rows with a
# missing, extra or quoted field, an edited metric, parameter or status, an
# edited batch table or batch CSV are refused, naming the shard, the line
# and what is wrong; a tampered OUT.partial loses its planted rows and the
# output stays exact; a batch repaired with --skip-existing keeps its files'
# steps and residuals; a FIFO, a forged shard=1/999999999, a foreign shard,
# CRLF ends and an edited input file are each named in a line or two; a
# study with a whole range missing is named; merge's memory does not grow
# with the rows; rows reach OUT.partial in blocks, not one write each.
# MECH_QUICK=1: all, merge's memory compared at 10^5 rows (not 2 x 10^5).
# (python3, when installed, plays the forger who recomputes digests:
# tests/merge_forge.py.)
# Run from the repository root:  MECH=build/mech sh tests/merge.sh
NAME=merge . tests/lib.sh

file=mechanisms/conveyor.yaml
metrics="--metric range:E.x"
sub="--vary l1=50mm:64mm:6 --vary l2=420mm:440mm:5"
forge=
command -v python3 >/dev/null 2>&1 && forge="python3 tests/merge_forge.py"
"$MECH" sweep $file $sub $metrics -j 1 -q -o "$tmp/ref.csv" 2>/dev/null
for k in 0 1 2; do
    "$MECH" sweep $file $sub $metrics -j 1 -q --shard $k/3 -o "$tmp/s.$k.csv" 2>/dev/null
done
has_line "$tmp/s.1.csv" '^# mech-digest rows=10 fnv1a64=[0-9a-f]\{16\}$' "a shard ends with its digest line"
if run "merge" 0 "$MECH" merge -o "$tmp/m.csv" "$tmp"/s.*.csv; then
    cmp -s "$tmp/m.csv" "$tmp/ref.csv" && pass || fail "merged shards differ from the unsharded run"
fi

# refused: exit 2, the pattern on standard error, nothing written, and
# (when given) exactly N problems
refused() {  # LABEL PATTERN [N] -- SHARD...
    label=$1 pattern=$2 count=
    shift 2
    [ "$1" != -- ] && { count=$1; shift; }
    shift
    rm -f "$tmp/bad.csv"
    if run "$label" 2 "$MECH" merge -o "$tmp/bad.csv" "$@"; then
        has_line "$tmp/err" "$pattern" "merge, $label"
        [ ! -e "$tmp/bad.csv" ] && pass || fail "merge, $label: a file was written"
        [ -z "$count" ] || has_line "$tmp/err" "^mech merge: $count problems*; nothing written\$" "merge, $label: $count problem(s)"
    fi
}
# shard 1/3 with line 5 (its row 3, variant 7) edited by sed script $2;
# with $3 = forge, its digest recomputed (a forger who knows FNV-1a)
edited() {  # NAME SED [forge]
    sed "$2" "$tmp/s.1.csv" >"$tmp/$1.csv"
    [ "$3" = forge ] && $forge redigest "$tmp/$1.csv"
}

# point 2: a field missing, a field too many, a quoted field (each alone:
# the digest recomputed; and as a hand edit, which the digest also names)
edited extra '5s/$/,1/'
refused "a field too many" "^mech merge: shard 1/3 (.*extra.csv): row 3 (line 5): 7 fields, the header has 6 (a field too many)\$" -- "$tmp/s.0.csv" "$tmp/extra.csv" "$tmp/s.2.csv"
has_line "$tmp/err" 'extra.csv): its rows do not match its digest line' "a field too many, by hand: the digest"
edited missing '5s/,361//'
refused "a field missing" 'row 3 (line 5): 5 fields, the header has 6 (a field missing)$' -- "$tmp/s.0.csv" "$tmp/missing.csv" "$tmp/s.2.csv"
edited quoted '5s/,ok,/,"ok,x",/'
refused "a quoted field" 'row 3 (line 5): a quoted field' -- "$tmp/s.0.csv" "$tmp/quoted.csv" "$tmp/s.2.csv"
if [ -n "$forge" ]; then
    edited extra2 '5s/$/,1/' forge
    refused "a field too many, digest recomputed" 'row 3 (line 5): 7 fields, the header has 6' 1 -- "$tmp/s.0.csv" "$tmp/extra2.csv" "$tmp/s.2.csv"
    edited quoted2 '5s/,ok,/,"ok",/' forge
    refused "a quoted field, digest recomputed" 'row 3 (line 5): a quoted field' 1 -- "$tmp/s.0.csv" "$tmp/quoted2.csv" "$tmp/s.2.csv"
fi

# point 3: what a row says is what was computed: a metric, a status, a
# parameter edited by hand (the digest), a parameter with the digest
# recomputed (the grid), the grid in the manifest with every digest
# recomputed (the grid hash)
edited metric '5s/,0\.038/,0.039/'
refused "an edited metric" 'metric.csv): its rows do not match its digest line (a row, the manifest or the header was edited' 1 -- "$tmp/s.0.csv" "$tmp/metric.csv" "$tmp/s.2.csv"
edited status '5s/,ok,/,no-assembly,/'
refused "an edited status" 'status.csv): its rows do not match its digest line' 1 -- "$tmp/s.0.csv" "$tmp/status.csv" "$tmp/s.2.csv"
edited param '5s/^7,0\.0528,/7,0.0529,/'
refused "an edited parameter" "row 3 (line 5): parameter 1 is '0.0529', the grid's value for variant 7 is 0.0528\$" -- "$tmp/s.0.csv" "$tmp/param.csv" "$tmp/s.2.csv"
if [ -n "$forge" ]; then
    edited param2 '5s/^7,0\.0528,0\.43,/7,0.0528,0.44,/' forge
    refused "an edited parameter, digest recomputed" "row 3 (line 5): parameter 2 is '0.44', the grid's value for variant 7 is 0.4299" 1 -- "$tmp/s.0.csv" "$tmp/param2.csv" "$tmp/s.2.csv"
    for k in 0 1 2; do  # the grid's arguments edited in every shard alike
        sed '1s/l1=50mm:64mm:6/l1=50mm:65mm:6/' "$tmp/s.$k.csv" >"$tmp/args.$k.csv"
        $forge redigest "$tmp/args.$k.csv"
    done
    refused "edited grid arguments, digests recomputed" "args.0.csv: its manifest's arguments do not give a grid that hashes to its grid=" -- "$tmp"/args.*.csv
fi
# --random: the samples recomputed from the seed and the manifest's tol=
rf=tests/sweep/tol-slider-crank.yaml
for k in 0 1; do
    "$MECH" sweep $rf --random 40 --seed 7 --metric max:B.x -q --shard $k/2 -o "$tmp/r.$k.csv" 2>/dev/null
done
"$MECH" sweep $rf --random 40 --seed 7 --metric max:B.x -q -o "$tmp/r.csv" 2>/dev/null
if run "merge --random shards" 0 "$MECH" merge -o "$tmp/rm.csv" "$tmp/r.0.csv" "$tmp/r.1.csv"; then
    cmp -s "$tmp/rm.csv" "$tmp/r.csv" && pass || fail "merged --random shards differ from the unsharded run"
fi
if [ -n "$forge" ]; then
    sed '4s/^2,0\.039992181/2,0.039992182/' "$tmp/r.0.csv" >"$tmp/rt.csv"
    $forge redigest "$tmp/rt.csv"
    refused "an edited --random sample, digest recomputed" "row 2 (line 4): parameter 1 is '0.039992182.*', the grid's value for variant 2 is 0.039992181" 1 -- "$tmp/rt.csv" "$tmp/r.1.csv"
fi

# point 4: --resume keeps only the rows of OUT.partial that check; planted
# rows (short, long, a <script> value) and an edited row are dropped with a
# message, and the output is the unbroken run's, byte for byte
whole="$tmp/p.whole.csv"
"$MECH" sweep $file $sub $metrics -j 1 -q --shard 0/1 -o "$whole" 2>/dev/null
head -n 12 "$whole" >"$tmp/p.csv.partial"  # manifest, header, 10 rows
echo "# mech-block rows=10 fnv1a64=0000000000000000" >>"$tmp/p.csv.partial"
if [ -n "$forge" ]; then
    $forge redigest "$tmp/p.csv.partial"
    { echo '13,0.05'
      echo '14,0.05,0.44,ok,361,0.03848922705268909,9'
      echo '15,<script>alert(1)</script>,0.42,ok,361,0.1'
      echo '6,0.0528,0.42,ok,361,0.1'  # variant 6 twice
      echo '31,0.0528,0.425,ok,361,0.1'
      echo '# mech-block rows=0 fnv1a64=0'; } >>"$tmp/p.csv.partial"
    $forge redigest "$tmp/p.csv.partial"
    if run "resume a partial file with planted rows (digests recomputed)" 0 "$MECH" sweep $file $sub $metrics -j 1 -q \
            --shard 0/1 --resume -o "$tmp/p.csv"; then
        cmp -s "$tmp/p.csv" "$whole" && pass || fail "resume with planted rows: not the unbroken run's output"
        grep -q 'script' "$tmp/p.csv" && fail "resume: a <script> value reached the output" || pass
        has_line "$tmp/err" 'p.csv.partial:14: row dropped (solved again): 2 fields, the header has 6 (a field missing)$' "resume: a short row"
        has_line "$tmp/err" 'p.csv.partial:15: row dropped (solved again): 7 fields, the header has 6 (a field too many)$' "resume: a long row"
        has_line "$tmp/err" "p.csv.partial:16: row dropped (solved again): parameter 1 is '<script>alert(1)</script>'" "resume: a <script> value"
        has_line "$tmp/err" 'p.csv.partial:17: row dropped (solved again): a variant given twice$' "resume: a variant twice"
        has_line "$tmp/err" 'p.csv.partial:18: row dropped (solved again): not a row of this shard$' "resume: a foreign variant"
        has_line "$tmp/err" 'p.csv.partial: 5 rows dropped, 10 kept' "resume: the count"
    fi
fi
# by hand: rows appended with no check line or a wrong one, a kept row
# edited: the blocks that do not check are dropped
head -n 12 "$whole" >"$tmp/q.csv.partial"
if [ -n "$forge" ]; then
    echo "# mech-block rows=10 fnv1a64=0" >>"$tmp/q.csv.partial"; $forge redigest "$tmp/q.csv.partial"
else
    cp "$whole" "$tmp/q.csv.partial"; sed -i '$d' "$tmp/q.csv.partial"  # no check line: all solved again
fi
sed -i '5s/,0\.0/,0.1/' "$tmp/q.csv.partial"
printf '3,0.05\n5,<script>x</script>,0.42,ok,361,0.1\n# mech-block rows=2 fnv1a64=0123456789abcdef\n7,0.05' >>"$tmp/q.csv.partial"
if run "resume a hand-tampered partial file" 0 "$MECH" sweep $file $sub $metrics -j 1 -q --shard 0/1 --resume -o "$tmp/q.csv"; then
    cmp -s "$tmp/q.csv" "$whole" && pass || fail "resume, hand-tampered: not the unbroken run's output"
    grep -q 'script' "$tmp/q.csv" && fail "resume, hand-tampered: a <script> value reached the output" || pass
    [ -z "$forge" ] || has_line "$tmp/err" "q.csv.partial:3-13: 10 rows dropped (solved again): their block's check line does not match them (edited?)" "resume, an edited block"
fi

# point 5: a batch repaired with --skip-existing: the kept files' steps,
# residual and time come from the row the earlier run wrote for that very
# CSV (its table, or the TABLE.partial of a killed run), or when there is
# none, steps from the CSV and nan: never "kept 0 0 0"
ls mechanisms/*.yaml >"$tmp/list"
bt() {  # K TABLE: shard K/2 of the list, --skip-existing
    "$MECH" batch -q -j 1 --shard "$1"/2 --files-from "$tmp/list" --out-dir "$tmp/csv" \
        --skip-existing --unsolvable-ok -o "$2" 2>/dev/null
}
bt 0 "$tmp/t.0.txt"; bt 1 "$tmp/t.1.txt"
cp "$tmp/t.1.txt" "$tmp/t.1.first"
first=$(awk '$2 == "ok" { print $1; exit }' "$tmp/t.1.txt")
rm "$tmp/csv/$first.csv"  # solved again; the others kept
bt 1 "$tmp/t.1.txt"
# every kept row has the steps and residual of the first run's row
awk 'NR == FNR { if ($2 == "ok") r[$1] = $3 " " $4; next }
     $2 == "kept" { n++; if (r[$1] != $3 " " $4) { print "kept " $1 ": " $3 " " $4 ", first run: " r[$1]; bad = 1 } }
     END { exit bad || n < 3 }' "$tmp/t.1.first" "$tmp/t.1.txt" >"$tmp/kept.diff" && pass ||
    fail "batch --skip-existing: kept rows lost their numbers: $(head -n 3 "$tmp/kept.diff")"
has_line "$tmp/t.1.txt" "^$first  *ok " "batch --skip-existing: the file whose CSV was removed is solved again"
if run "merge of a repaired batch" 0 "$MECH" merge -o "$tmp/tm.txt" "$tmp/t.0.txt" "$tmp/t.1.txt"; then
    awk '$2 == "kept" && ($3 == 0 || $4 == 0) { bad = 1 } END { exit bad }' "$tmp/tm.txt" && pass ||
        fail "merged batch table: a kept file with 0 steps or residual: $(grep ' kept ' "$tmp/tm.txt" | head -n 1)"
fi
rm "$tmp/t.1.txt"  # no recorded row left: steps from the CSVs, nan for the rest
bt 1 "$tmp/t.1.txt"
awk '$2 == "kept" { n++; if ($3 < 1 || $4 != "nan" || $5 != "nan") bad = 1 } END { exit bad || n < 3 }' "$tmp/t.1.txt" && pass ||
    fail "batch --skip-existing, no recorded row: $(grep ' kept ' "$tmp/t.1.txt" | head -n 1)"
# a killed shard's TABLE.partial gives the numbers of the rows it holds
mkdir "$tmp/many"
for i in $(seq 100 139); do cp $file "$tmp/many/c$i.yaml"; done
ls "$tmp"/many/*.yaml >"$tmp/mlist"
kb() { exec "$MECH" batch -j 1 -q --shard 0/1 --files-from "$tmp/mlist" --out-dir "$tmp/mcsv" \
    --skip-existing --unsolvable-ok -o "$tmp/k.txt"; }
(kb 2>/dev/null) &
pid=$!
for i in $(seq 600); do
    [ -f "$tmp/k.txt.partial" ] && [ "$(grep -vc '^#' "$tmp/k.txt.partial")" -ge 4 ] && break
    sleep 0.05
done
kill -KILL $pid 2>/dev/null
wait $pid 2>/dev/null
if [ ! -e "$tmp/k.txt" ]; then
    cp "$tmp/k.txt.partial" "$tmp/k.recorded"
    (kb 2>/dev/null)
    awk 'NR == FNR { if ($2 == "ok") r[$1] = $3 " " $4 " " $5; next }
         $2 == "kept" && ($1 in r) { n++; if (r[$1] != $3 " " $4 " " $5) bad = 1 }
         END { exit bad || n < 3 }' "$tmp/k.recorded" "$tmp/k.txt" && pass ||
        fail "batch repaired after a kill: kept rows without the numbers of the killed run's rows"
else
    echo "merge.sh: the batch finished before it was killed, the kill test skipped"
fi

# point 3, batch: an edited table value, an edited CSV value
sed '3s/ok    /FAILED/' "$tmp/t.0.txt" >"$tmp/te.txt"
refused "an edited batch table" 'te.txt): its rows do not match its digest line' 1 -- "$tmp/te.txt" "$tmp/t.1.txt"
kept_csv=$(awk '$2 == "ok" && $NF != "-" { print $1; exit }' "$tmp/t.0.txt")
cp "$tmp/csv/$kept_csv.csv" "$tmp/keep.csv"
sed -i '3s/^\([^,]*\),\([0-9]\)/\1,9/' "$tmp/csv/$kept_csv.csv"
refused "an edited batch CSV" "($kept_csv): .*csv/$kept_csv.csv is not the CSV its shard wrote (its bytes differ from the hash in the summary" 1 -- "$tmp/t.0.txt" "$tmp/t.1.txt"
cp "$tmp/keep.csv" "$tmp/csv/$kept_csv.csv"

# point 7: a FIFO is refused at once (no hang: killed after 20 s)
if mkfifo "$tmp/fifo" 2>/dev/null; then
    rm -f "$tmp/bad.csv"
    "$MECH" merge -o "$tmp/bad.csv" "$tmp/s.0.csv" "$tmp/fifo" "$tmp/s.2.csv" >"$tmp/out" 2>"$tmp/err" &
    mpid=$!
    i=0
    while kill -0 $mpid 2>/dev/null && [ $i -lt 200 ]; do sleep 0.1; i=$((i + 1)); done
    if kill -0 $mpid 2>/dev/null; then
        kill -KILL $mpid
        fail "merge with a FIFO as a shard: still waiting after 20 s"
    else
        wait $mpid
        [ $? -eq 2 ] && [ ! -e "$tmp/bad.csv" ] && pass || fail "merge with a FIFO as a shard: not refused"
        has_line "$tmp/err" '^mech merge: .*fifo is a FIFO, not a shard.s file' "merge with a FIFO as a shard: message"
    fi
fi
# a forged shard=1/999999999: one line with ranges, at once
sed '1s|shard=1/3|shard=1/999999999|' "$tmp/s.1.csv" >"$tmp/forged.csv"
# (the old merge printed a line per missing shard, 300 000 a second: cut at 30 s)
limit=
command -v timeout >/dev/null 2>&1 && limit="timeout 30"
if run "a forged shard count, alone" 2 $limit "$MECH" merge -o "$tmp/bad.csv" "$tmp/forged.csv"; then
    has_line "$tmp/err" '^mech merge: shards 0, 2..999999998 of 999999999 missing (999999998 of 999999999 shards)$' "a forged shard count: one line with ranges"
    [ "$(wc -l <"$tmp/err")" -le 2 ] && pass || fail "a forged shard count: $(wc -l <"$tmp/err") lines of messages"
fi
refused "a forged shard count, with the run" 'splits the run in 3 shards, shard 1/999999999 (.*forged.csv) in 999999999' -- "$tmp/s.0.csv" "$tmp/forged.csv" "$tmp/s.2.csv"
# one foreign shard: named against the run, and the present shards are not "missing"
"$MECH" sweep $file --vary l1=50mm:64mm:6 --vary l2=420mm:440mm:6 $metrics -j 1 -q --shard 1/3 -o "$tmp/foreign.csv" 2>/dev/null
refused "a foreign shard first" '^mech merge: shard 1/3 (.*foreign.csv) is not from the same run as shard 0/3 (.*s.0.csv): its grid differs$' 2 -- "$tmp/foreign.csv" "$tmp/s.0.csv" "$tmp/s.2.csv"
has_line "$tmp/err" '^mech merge: shard 1/3 missing$' "a foreign shard: the one really missing"
refused "a foreign shard besides the whole run" 'foreign.csv) is not from the same run' 1 -- "$tmp/s.0.csv" "$tmp/s.1.csv" "$tmp/s.2.csv" "$tmp/foreign.csv"
grep -q 'missing' "$tmp/err" && fail "a foreign shard besides the whole run: a shard called missing" || pass
# CRLF ends are read (the digest does not count the CR)
for k in 0 1 2; do sed 's/$/\r/' "$tmp/s.$k.csv" >"$tmp/crlf.$k.csv"; done
if run "merge of CRLF shards" 0 "$MECH" merge -o "$tmp/crlf.csv" "$tmp/crlf.0.csv" "$tmp/s.1.csv" "$tmp/crlf.2.csv"; then
    cmp -s "$tmp/crlf.csv" "$tmp/ref.csv" && pass || fail "merge of CRLF shards: not the unsharded run's output"
fi
# a batch merge names the input file that changed between two shards
cp "$tmp/many/c102.yaml" "$tmp/c102.orig"
"$MECH" batch -q -j 1 --shard 0/2 --files-from "$tmp/mlist" -o "$tmp/in.0.txt" 2>/dev/null
echo "# edited" >>"$tmp/many/c102.yaml"
"$MECH" batch -q -j 1 --shard 1/2 --files-from "$tmp/mlist" -o "$tmp/in.1.txt" 2>/dev/null
refused "a batch input file edited between shards" '^mech merge: shard 1/2 (.*in.1.txt) is not from the same run as shard 0/2 (.*in.0.txt): its input file (its contents) differs: c102 (index 2)$' -- "$tmp/in.0.txt" "$tmp/in.1.txt"
cp "$tmp/c102.orig" "$tmp/many/c102.yaml"

# point 8: a study split with --index-offset: a whole range missing is
# named (without --study it cannot be seen)
"$MECH" sweep $file --vary l1=50mm:64mm:6 --list l2=420mm,425mm,430mm $metrics -j 1 -q -o "$tmp/g1.csv" --shard 0/1 2>/dev/null
"$MECH" sweep $file --vary l1=50mm:64mm:6 --list l2=435mm,440mm $metrics -j 1 -q --index-offset 18 -o "$tmp/g2.csv" 2>/dev/null
printf '# the study: l2 from 420 to 445 mm in three runs\n0 18\n18 12\n30 6\n' >"$tmp/study"
printf '0 18\n18 12\n' >"$tmp/study2"
run "two runs of a three-run study, without --study" 0 "$MECH" merge -o "$tmp/g.csv" "$tmp/g1.csv" "$tmp/g2.csv" && pass
refused "a study's range missing" "study:4: range 30..35 (--index-offset 30, 6 variants) missing: no shard of it given\$" 1 -- --study "$tmp/study" "$tmp/g1.csv" "$tmp/g2.csv"
if run "a whole study" 0 "$MECH" merge --study "$tmp/study2" -o "$tmp/g.csv" "$tmp/g1.csv" "$tmp/g2.csv"; then
    [ "$(wc -l <"$tmp/g.csv")" -eq 31 ] && pass || fail "a whole study: $(wc -l <"$tmp/g.csv") lines"
fi
refused "a study's first range missing" "study2:1: range 0..17 (--index-offset 0, 18 variants) missing" -- --study "$tmp/study2" "$tmp/g2.csv"

# ---- HDF5 (docs/cli.md, "HDF5 output"): a sweep written as .h5 holds the
# CSV's numbers and words exactly; its shards, as .h5 (and mixed with CSV
# shards), merge to the unsharded run, as CSV or .h5; mismatched shards are
# refused as CSV ones are; an output that is an input (exit 2) and a missing
# directory (exit 3) write nothing. (tests/unit/test_output_h5.c opens a
# sweep's .h5 with the HDF5 library: the attributes.)
h5m="--metric range:E.x --metric transmission:coupler,tray"
"$MECH" sweep $file $sub $h5m -j 1 -q -o "$tmp/h5ref.csv" 2>/dev/null
if run "sweep -o OUT.h5" 0 "$MECH" sweep $file $sub $h5m -j 1 -q -o "$tmp/h5ref.h5"; then
    run "sweep: HDF5 against the CSV, exactly" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/h5ref.h5" "$tmp/h5ref.csv" &&
        has_line "$tmp/out" "^compare: 7 columns, 30 rows: all within" "sweep HDF5: every column (status too) and row"
    [ -e "$tmp/h5ref.h5.partial" ] && fail "sweep -o OUT.h5 left OUT.h5.partial" || pass
    ls "$tmp"/h5ref.h5.tmp* >/dev/null 2>&1 && fail "a temporary file was left beside h5ref.h5" || pass
    [ "$(head -c 4 "$tmp/h5ref.h5" | od -An -c | tr -d ' ')" = "211HDF" ] && pass || fail "h5ref.h5 has no HDF5 signature"
fi
for k in 0 1 2; do
    "$MECH" sweep $file $sub $h5m -j 1 -q --shard $k/3 -o "$tmp/h5s.$k.h5" 2>/dev/null
done
"$MECH" sweep $file $sub $h5m -j 1 -q --shard 1/3 -o "$tmp/h5s.1.csv" 2>/dev/null
for out in csv h5; do
    if run "merge HDF5 shards -o OUT.$out" 0 "$MECH" merge -o "$tmp/h5m.$out" "$tmp"/h5s.*.h5; then
        run "merged HDF5 shards ($out) equal the unsharded run" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/h5m.$out" "$tmp/h5ref.csv" &&
            has_line "$tmp/out" "^compare: 7 columns, 30 rows: all within" "merged HDF5 shards: every row"
    fi
done
if run "merge HDF5 and CSV shards" 0 "$MECH" merge -o "$tmp/h5mix.h5" "$tmp/h5s.0.h5" "$tmp/h5s.1.csv" "$tmp/h5s.2.h5"; then
    run "mixed shards equal the unsharded run" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/h5mix.h5" "$tmp/h5ref.h5"
fi
"$MECH" sweep $file $sub --metric range:E.x -j 1 -q --shard 2/3 -o "$tmp/h5other.2.h5" 2>/dev/null
refused "HDF5 shards of two runs" "is not from the same run as .*: its arguments differ" -- \
    "$tmp/h5s.0.h5" "$tmp/h5s.1.h5" "$tmp/h5other.2.h5"
refused "an HDF5 shard missing" "shard 2/3 missing" 1 -- "$tmp/h5s.0.h5" "$tmp/h5s.1.h5"
refused "an unsharded .h5 is no shard" "no '# mech-manifest' line" -- "$tmp/h5ref.h5" "$tmp/h5s.1.h5"
cp "$tmp/h5s.0.h5" "$tmp/h5in.h5"
if run "merge -o SHARD.h5" 2 "$MECH" merge -o "$tmp/h5in.h5" "$tmp/h5in.h5" "$tmp/h5s.1.h5" "$tmp/h5s.2.h5"; then
    cmp -s "$tmp/h5in.h5" "$tmp/h5s.0.h5" && pass || fail "merge -o SHARD.h5 changed the shard"
fi
if run "merge -o MISSING/OUT.h5" 3 "$MECH" merge -o "$tmp/nodir/m.h5" "$tmp"/h5s.*.h5; then
    [ -e "$tmp/nodir" ] && fail "merge -o MISSING/OUT.h5 made something" || pass
fi
if run "sweep -o MISSING/OUT.h5" 3 "$MECH" sweep $file $sub $h5m -j 1 -q -o "$tmp/nodir/s.h5"; then
    [ -e "$tmp/nodir" ] && fail "sweep -o MISSING/OUT.h5 made something" || pass
fi
cp $file "$tmp/in.h5"
run "sweep: the output is the input" 2 "$MECH" sweep "$tmp/in.h5" $sub -q -o "$tmp/in.h5" &&
    cmp -s "$tmp/in.h5" $file && pass
# --resume with OUT.h5: OUT.h5.partial holds CSV rows as for a CSV
if run "sweep --resume -o OUT.h5 with nothing to resume" 0 "$MECH" sweep $file $sub $h5m -j 1 -q --resume -o "$tmp/h5res.h5"; then
    run "resumed .h5: the same numbers" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/h5res.h5" "$tmp/h5ref.csv"
fi
# batch -o TABLE.h5: the summary (text and numbers); --shard with it refused
if run "batch -o TABLE.h5" 0 "$MECH" batch -q mechanisms/fourbar.yaml mechanisms/slider-crank.yaml -o "$tmp/b.h5"; then
    run "batch TABLE.h5 read back" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/b.h5" "$tmp/b.h5" &&
        has_line "$tmp/out" "^compare: 6 columns, 2 rows: all within" "batch TABLE.h5: 6 columns, 2 rows"
    [ -e "$tmp/b.h5.partial" ] && fail "batch -o TABLE.h5 left TABLE.h5.partial" || pass
fi
run "batch --shard -o TABLE.h5" 2 "$MECH" batch -q mechanisms/fourbar.yaml --shard 0/2 -o "$tmp/bs.h5" &&
    has_line "$tmp/err" "a shard's table is text" "batch --shard -o TABLE.h5: why it is refused"

# point 8: merge streams: its peak memory at 2 x 10^5 rows is that at
# 2 x 10^4 (made-up shards, tests/merge_forge.py gen; the old merge held
# every row: about 10 MB more; MECH_QUICK=1: 10^5 rows, 5 MB more)
# (not under a sanitizer: its own memory moves by megabytes)
if [ -n "$forge" ] && [ -x /usr/bin/time ] && [ -z "$MECH_SANITIZE" ]; then
    mkdir "$tmp/small" "$tmp/big"
    bigb=500
    [ -n "$MECH_QUICK" ] && bigb=250
    $forge gen "$tmp/small" 4 200 100 "$(sed -n 's/.*version=\([^ ]*\).*/\1/p;q' "$tmp/s.0.csv")"
    $forge gen "$tmp/big" 4 400 $bigb "$(sed -n 's/.*version=\([^ ]*\).*/\1/p;q' "$tmp/s.0.csv")"
    /usr/bin/time -f %M -o "$tmp/rss.small" "$MECH" merge -o "$tmp/small.csv" "$tmp"/small/s.*.csv 2>/dev/null
    /usr/bin/time -f %M -o "$tmp/rss.big" "$MECH" merge -o "$tmp/big.csv" "$tmp"/big/s.*.csv 2>/dev/null
    [ "$(wc -l <"$tmp/big.csv")" -eq $((400 * bigb + 1)) ] && pass || fail "merge of $((400 * bigb)) rows: $(wc -l <"$tmp/big.csv") lines"
    small=$(tail -n 1 "$tmp/rss.small") big=$(tail -n 1 "$tmp/rss.big")
    [ $((big - small)) -lt 1024 ] && pass || fail "merge's peak memory grows with the rows: $small kB at 2e4, $big kB at $((400 * bigb))"
fi

# point 8: rows reach OUT.partial in blocks (a write a second or per 64
# KiB), not one write per row: 30 variants, a few writes
if command -v strace >/dev/null 2>&1 &&
        strace -f -qq -e trace=pwrite64 -o "$tmp/strace" "$MECH" sweep $file $sub $metrics -j 2 -q -o "$tmp/st.csv" 2>/dev/null; then
    writes=$(grep -c 'pwrite64(' "$tmp/strace")
    [ "$writes" -ge 2 ] && [ "$writes" -le 4 ] && pass || fail "OUT.partial: $writes writes for 30 rows"
fi

summary
