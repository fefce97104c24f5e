#!/bin/sh
# tests/sweep_random.sh: `mech sweep --random N` against the first-order
# stack-up of `mech solve --tolerances`. The offset slider-crank with
# r = 40 +- 0.05 mm and l = 120 +- 0.1 mm at crank angle 240 deg
# (tests/sweep/tol-slider-crank.yaml), 10^4 samples: every sample's
# deviation of B.x, B.vx, B.ax from the nominal stays within the worst case
# (to 1e-3 of it: the stack-up is first order, the samples are not), the
# largest comes within 10 % of it, and the samples' standard deviation is
# RSS/sqrt(3) (uniform errors within +-tol) to 3 %. Then: the same seed
# gives the same bytes with -j 1 and -j 2 and when sharded and merged;
# another seed other rows; the refusals.
# Run from the repository root:  MECH=build/mech sh tests/sweep_random.sh
NAME=sweep_random . tests/lib.sh

file=tests/sweep/tol-slider-crank.yaml
n=10000
[ -n "$MECH_SANITIZE" ] && n=500
metrics="--metric max:B.x --metric max:B.vx --metric max:B.ax"

# column NAME of a CSV: its index (1-based), from the header
column() { grep -v '^#' "$1" | head -n 1 | tr ',' '\n' | grep -n "^$2 \[" | cut -d: -f1; }

if run "solve --tolerances" 0 "$MECH" solve $file --tolerances --outputs B -q -o "$tmp/tol.csv" &&
   run "sweep --random" 0 "$MECH" sweep $file --random $n --seed 7 $metrics -q -o "$tmp/rand.csv"; then
    pass
    rows=$(($(grep -vc '^#' "$tmp/rand.csv") - 1))
    [ "$rows" -eq "$n" ] && pass || fail "--random $n: $rows rows"
    ok=$(grep -c ',ok,2,' "$tmp/rand.csv")
    [ "$ok" -eq "$n" ] && pass || fail "--random $n: $ok variants ok"
    head -n 1 "$tmp/rand.csv" | grep -q '^variant \[-\],r \[m\],l \[m\],status \[-\],rows \[-\],max:B.x \[m\],max:B.vx \[m/s\],max:B.ax \[m/s^2\]$' \
        && pass || fail "--random header: $(head -n 1 "$tmp/rand.csv")"
    for col in B.x B.vx B.ax; do
        c0=$(column "$tmp/tol.csv" "$col")
        cw=$(column "$tmp/tol.csv" "worst($col)")
        cr=$(column "$tmp/tol.csv" "rss($col)")
        cm=$(column "$tmp/rand.csv" "max:$col")
        # the samples' r and l within their tolerances, too
        verdict=$(awk -F, -v c0="$c0" -v cw="$cw" -v cr="$cr" -v cm="$cm" '
            FNR == 2 && FILENAME ~ /tol.csv$/ { nom = $c0; worst = $cw; rss = $cr; next }
            FILENAME ~ /rand.csv$/ && FNR > 1 {
                d = $cm - nom; n++; s += d; ss += d * d
                a = d < 0 ? -d : d; if (a > big) big = a
                if ($2 < 0.04 - 0.00005 || $2 > 0.04 + 0.00005 || $3 < 0.12 - 0.0001 || $3 > 0.12 + 0.0001) out++
            }
            END {
                mean = s / n; sd = sqrt((ss - n * mean * mean) / (n - 1)); want = rss / sqrt(3)
                printf "largest %.6g worst %.6g (%.4f) sd %.6g rss/sqrt3 %.6g (%.4f) outside %d: ",
                       big, worst, big / worst, sd, want, sd / want, out
                print (big <= worst * 1.001 && big >= 0.9 * worst && sd > 0.97 * want && sd < 1.03 * want && out == 0) ? "ok" : "bad"
            }' "$tmp/tol.csv" "$tmp/rand.csv")
        [ -n "$MECH_TEST_VERBOSE" ] && echo "$col: $verdict"
        case $verdict in *ok) pass ;; *) fail "--random against --tolerances, $col: $verdict" ;; esac
    done
fi

# reproducible: the same seed, other workers, sharded and merged; another seed
sub="--random 40 --seed 99 --metric max:B.x"
"$MECH" sweep $file $sub -q -j 1 -o "$tmp/j1.csv" 2>/dev/null
"$MECH" sweep $file $sub -q -j 2 -o "$tmp/j2.csv" 2>/dev/null
cmp -s "$tmp/j1.csv" "$tmp/j2.csv" && pass || fail "--random: -j 1 and -j 2 differ"
"$MECH" sweep $file $sub -q --shard 0/2 -o "$tmp/s0.csv" 2>/dev/null
"$MECH" sweep $file $sub -q --shard 1/2 -o "$tmp/s1.csv" 2>/dev/null
if "$MECH" merge -o "$tmp/merged.csv" "$tmp/s0.csv" "$tmp/s1.csv" 2>"$tmp/err"; then
    cmp -s "$tmp/j1.csv" "$tmp/merged.csv" && pass || fail "--random: the merged shards differ from one run"
else
    fail "--random: merge of two shards: $(head -n 1 "$tmp/err")"
fi
"$MECH" sweep $file --random 40 --seed 100 --metric max:B.x -q -o "$tmp/other.csv" 2>/dev/null
cmp -s "$tmp/j1.csv" "$tmp/other.csv" && fail "--random: seeds 99 and 100 give the same rows" || pass

# refusals
run "--random with --vary" 2 "$MECH" sweep $file --random 5 --vary r=39mm:41mm:3 && pass
run "--random without tolerances" 2 "$MECH" sweep mechanisms/fourbar.yaml --random 5 && pass
has_line "$tmp/err" "no parameter of 'mechanisms/fourbar.yaml' has a tolerance" "--random without tolerances"
run "--random 0" 2 "$MECH" sweep $file --random 0 && pass
run "--seed x" 2 "$MECH" sweep $file --random 5 --seed x && pass

summary
