#!/bin/sh
# tests/browser/watch.sh: the live page of `mech watch` in headless chromium
# (no network but the loopback address the page comes from), while the file
# it watches changes on disk.
#
# A copy of mechanisms/offset-slider-crank.yaml is watched (--test-colours);
# tests/browser/watch_check.py opens the page once and checks, in that same
# page: version 1's values (row 0 of `mech solve`, bit for bit) and points
# (DOM within 0.15 px, screenshot discs within 1 px); v2 (crank radius 45 mm
# instead of 40) saved as editors do (a temporary file renamed over it): the
# page follows within 2 s with v2's values and points; a broken file (an
# unknown unit) written in place: the error FILE:LINE:COLUMN in the page and
# v2's drawing kept; v1 again. Then SIGTERM: mech watch exits 0.
#
# Needs (Debian): chromium, libxml2-utils (xmllint), python3, fonts-dejavu-core.
# usage: MECH=build/mech sh tests/browser/watch.sh   (writes into $OUT,
# default build/browser-watch)
set -u
cd "$(dirname "$0")/../.."   # the repository root: MECH and OUT are relative to it
MECH=${MECH:-build/mech}
OUT=${OUT:-build/browser-watch}
CHROMIUM=${CHROMIUM:-chromium}
. tests/browser/lib.sh

src=mechanisms/offset-slider-crank.yaml
echo "== mech watch $src (a copy)"
cp "$src" "$OUT/v1.yaml"
sed 's/^  r: 40 mm /  r: 45 mm /' "$src" >"$OUT/v2.yaml"
sed 's/^  e: 30 mm /  e: 30 mmm /' "$src" >"$OUT/broken.yaml"
cmp -s "$OUT/v1.yaml" "$OUT/v2.yaml" && fail "v2.yaml is v1.yaml (the edit did not apply)"
cmp -s "$OUT/v1.yaml" "$OUT/broken.yaml" && fail "broken.yaml is v1.yaml (the edit did not apply)"
points=$("$MECH" animate "$src" --frame 0 --test-colours | sed -n 's/.*data-point="\([^"]*\)".*/\1/p' |
    paste -sd, -)
for v in v1 v2; do
    "$MECH" solve "$OUT/$v.yaml" -o "$OUT/solve-$v.csv" || fail "mech solve $v.yaml"
    "$MECH" solve "$OUT/$v.yaml" --outputs "$points" --level positions \
        -o "$OUT/positions-$v.csv" || fail "mech solve $v.yaml --outputs $points"
done

cp "$OUT/v1.yaml" "$OUT/w.yaml"
"$MECH" watch "$OUT/w.yaml" --test-colours >"$OUT/url.txt" 2>"$OUT/watch.err" &
pid=$!
i=0
while [ ! -s "$OUT/url.txt" ] && [ $i -lt 100 ]; do
    sleep 0.1
    i=$((i + 1))
done
url=$(head -n 1 "$OUT/url.txt")
case $url in
http://127.0.0.1:*/) ;;
*) fail "mech watch printed '$url', not its address" ;;
esac
python3 tests/browser/watch_check.py "$url" "$OUT/w.yaml" "$OUT" "$CHROMIUM" >"$OUT/check.txt" ||
    fail "the page of mech watch (chromium's log: $OUT/chromium.log)"
grep -v '^moved ' "$OUT/check.txt"  # the disc centres: in check.txt
kill -TERM $pid
wait $pid
status=$?
[ $status -eq 0 ] || fail "mech watch exited $status on SIGTERM, not 0"
echo "  SIGTERM: mech watch exited $status"

if [ "$fails" -ne 0 ]; then
    echo "tests/browser/watch.sh: $fails failure(s); files and screenshots in $OUT"
    cat "$OUT/watch.err"
    exit 1
fi
echo "tests/browser/watch.sh: all passed (files and screenshots in $OUT)"
