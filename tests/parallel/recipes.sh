#!/bin/sh
# tests/parallel/recipes.sh: the GNU Parallel recipes of docs/batch.md, run
# as written (taken from the file) on the local host (-S :): the merged
# sweep equals the unsharded run; a shard killed while it runs makes the
# recipe fail and `mech merge` name it; the repair recipe (parallel
# --resume-failed) reruns just that shard, which continues its partial file,
# and the merge then equals the unsharded run; the batch recipe's merged
# table equals one batch's, and a batch shard killed while it runs is named
# by merge and repaired by the batch repair recipe. Skipped (exit 0, said) without `parallel`.
# The sizes are the same under MECH_QUICK=1: the kill needs shards that run
# long enough to be seen running (with 20 x 20 variants a loaded machine
# saw every shard end before one could be killed).
# Run from the repository root:  MECH=build/mech sh tests/parallel/recipes.sh
NAME=parallel . tests/lib.sh
. tests/recipe.sh

if ! command -v parallel >/dev/null 2>&1; then
    echo "parallel: GNU Parallel is not installed (Debian package parallel); skipped"
    exit 0
fi
n1=100 copies=400
# sized NAME: the recipe NAME with the sweep's l1 over n1 values
sized() {
    recipe "$1" | sed "s/--vary l1=50mm:64mm:100 /--vary l1=50mm:64mm:$n1 /"
}
scratch
cd "$work" || exit 2
build/mech sweep mechanisms/conveyor.yaml --vary l1=50mm:64mm:$n1 --vary l2=420mm:440mm:20 \
    --metric range:E.x -q -o "$tmp/ref.csv" || fail "the unsharded sweep"

# the sweep recipe with one shard killed while it runs
sized parallel-sweep >"$tmp/sweep.sh"
grep -q -- "--vary l1=50mm:64mm:$n1 " "$tmp/sweep.sh" && pass || fail "no recipe parallel-sweep over l1=50mm:64mm:100 in docs/batch.md"
sh "$tmp/sweep.sh" >"$tmp/out" 2>"$tmp/err" &
pid=$!
set -- $(kill_running_shard 8 60)
k=$1 victim=$2
wait $pid
status=$?
if [ -n "$victim" ]; then
    [ "$status" -ne 0 ] && pass || fail "the recipe with shard $k killed exits 0"
    has_line "$tmp/err" "^mech merge: shard $k/8 missing" "merge after shard $k was killed"
    [ ! -e out/sweep.csv ] && pass || fail "merge wrote out/sweep.csv with shard $k missing"
    [ -f "out/sweep.$k.csv.partial" ] && pass || fail "the killed shard left no partial file"
else
    fail "no shard was seen running to kill it"
fi

sized parallel-sweep-repair >"$tmp/repair.sh"
if run "the repair recipe" 0 sh "$tmp/repair.sh"; then
    cmp -s out/sweep.csv "$tmp/ref.csv" && pass || fail "the repaired merge differs from the unsharded run"
    [ ! -e "out/sweep.$k.csv.partial" ] && pass || fail "the repaired shard's partial file stays"
fi
# the log shows the killed shard run twice, the others once
runs=$(awk -F'\t' 'NR > 1 { n[$NF]++ } END { for (c in n) print n[c] }' out/sweep.joblog | sort | uniq -c | tr -s ' ' | sed 's/^ //')
[ "$runs" = "$(printf '7 1\n1 2')" ] && pass || fail "parallel --resume-failed: runs per shard $runs"

# the batch recipe
recipe parallel-batch >"$tmp/batch.sh"
if run "the batch recipe" 0 sh "$tmp/batch.sh"; then
    build/mech batch -q --files-from out/files.txt >"$tmp/one.txt" 2>/dev/null
    [ "$(untimed out/summary.txt)" = "$(untimed "$tmp/one.txt")" ] && pass ||
        fail "the merged batch table differs from one batch's"
    [ "$(ls out/csv | wc -l)" -eq "$(wc -l <out/files.txt)" ] && pass || fail "the batch recipe: CSVs missing"
    # each shard wrote its table whole with -o (rows first to TABLE.partial)
    [ "$(ls out/summary.*.txt | wc -l)" -eq 4 ] && [ -z "$(ls out/summary.*.partial 2>/dev/null)" ] && pass ||
        fail "the batch recipe: tables $(ls out/summary.* | tr '\n' ' ')"
fi

# the batch recipe over a list long enough to kill a shard while it runs
# (mechanisms/ here: the repository's files and 400 conveyor copies)
rm -rf out
rm mechanisms  # the link to the repository's directory, not the files
mkdir mechanisms
cp "$repo"/mechanisms/*.yaml mechanisms/
for i in $(seq 100 $((99 + copies))); do cp "$repo/mechanisms/conveyor.yaml" "mechanisms/c$i.yaml"; done
sh "$tmp/batch.sh" >"$tmp/out" 2>"$tmp/err" &
pid=$!
set -- $(kill_running_shard 4 60 'summary.%s.txt.partial')
k=$1 victim=$2
wait $pid
status=$?
if [ -n "$victim" ]; then
    [ "$status" -ne 0 ] && pass || fail "the batch recipe with shard $k killed exits 0"
    has_line "$tmp/err" "^mech merge: shard $k/4 missing" "merge after batch shard $k was killed"
    [ ! -e out/summary.txt ] && pass || fail "merge wrote out/summary.txt with shard $k missing"
    [ -f "out/summary.$k.txt.partial" ] && [ ! -e "out/summary.$k.txt" ] && pass ||
        fail "the killed batch shard: $(ls out/summary.$k.* 2>&1 | tr '\n' ' ')"
else
    fail "no batch shard was seen running to kill it"
fi
recipe parallel-batch-repair >"$tmp/brepair.sh"
[ -s "$tmp/brepair.sh" ] && pass || fail "no recipe parallel-batch-repair in docs/batch.md"
if run "the batch repair recipe" 0 sh "$tmp/brepair.sh"; then
    build/mech batch -q --files-from out/files.txt >"$tmp/one.txt" 2>/dev/null
    # file and status (a row kept by --skip-existing has no steps nor times)
    [ "$(awk '{ print $1, $2 }' out/summary.txt | sed 's/ kept$/ ok/')" = "$(awk '{ print $1, $2 }' "$tmp/one.txt")" ] && pass ||
        fail "the repaired batch merge differs from one batch's table"
    [ "$(ls out/csv | grep -c '\.csv$')" -eq "$(wc -l <out/files.txt)" ] && pass ||
        fail "the batch repair: $(ls out/csv | grep -c '\.csv$') CSVs for $(wc -l <out/files.txt) files"
    # known problem (src/output/output.c, reported): SIGTERM can leave a NAME.csv.tmpXXXXXX
    left=$(ls out/csv | grep -v '\.csv$' | tr '\n' ' ')
    [ -n "$left" ] && echo "parallel: note: the killed shard left temporary files: $left"
fi
runs=$(awk -F'\t' 'NR > 1 { n[$NF]++ } END { for (c in n) print n[c] }' out/batch.joblog | sort | uniq -c | tr -s ' ' | sed 's/^ //')
[ "$runs" = "$(printf '3 1\n1 2')" ] && pass || fail "parallel --resume-failed (batch): runs per shard $runs"
cd "$repo" || exit 2
summary
