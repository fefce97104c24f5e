#!/bin/sh
# tests/browser/report.sh: `mech report` pages opened in headless chromium
# with no network (no proxy, every host unresolvable; the page's own
# Content-Security-Policy forbids every load from elsewhere too).
#
# For mechanisms/stirling.yaml (crank-driven, sliders) and
# mechanisms/offset-slider-crank.yaml:
#   1. the page (--test-colours: every point of the animation a disc of its
#      own colour) is well-formed XML (xmllint);
#   2. for slider positions K1 = 0 and K2 = rows/3, chromium opens
#      REPORT.html#row=K&test: the page's script moves the slider to K
#      through its input event and writes what it shows into the DOM
#      (--dump-dom); tests/browser/report_check.py checks that the values
#      shown are row K of `mech solve`'s CSV bit for bit, that every point
#      drawn is at row K's position (`mech solve --outputs <all points>
#      --level positions`), and, in a screenshot, that each disc's pixel
#      centroid is within 1 px of row K's position; between K1 and K2 the
#      discs moved;
#   3. Play (REPORT.html#play&test: the button clicked through the DOM): 1 s
#      later the animation has run and the slider has followed it (at the
#      row of the animation's time) with the values of that row;
#   4. a screenshot of the whole page (device scale 0.5): the animation and
#      every figure (as many as `mech plot` draws) are drawn, not blank.
#
# Needs (Debian): chromium, libxml2-utils (xmllint), python3, fonts-dejavu-core.
# usage: MECH=build/mech sh tests/browser/report.sh   (writes into $OUT,
# default build/browser-report)
set -u
cd "$(dirname "$0")/../.."   # the repository root: MECH and OUT are relative to it
MECH=${MECH:-build/mech}
OUT=${OUT:-build/browser-report}
CHROMIUM=${CHROMIUM:-chromium}
CHECK="python3 tests/browser/report_check.py"
. tests/browser/lib.sh

# page_height DOM.html: the page's height in CSS px, from the test report
page_height() {
    sed -n 's/.*"page":\[[0-9.]*,\([0-9.]*\)\].*/\1/p' "$1" | head -n 1 | cut -d. -f1
}

# anim_bottom DOM.html: the bottom of the animation in the page, CSS px
anim_bottom() {
    sed -n 's/.*"anim":\[[-0-9.e]*,\([-0-9.e]*\),[-0-9.e]*,\([-0-9.e]*\)\].*/\1 \2/p' "$1" |
        head -n 1 | awk '{ printf "%d\n", $1 + $2 + 20 }'
}

for name in ${REPORT_MECHS:-stirling offset-slider-crank}; do
    yaml=mechanisms/$name.yaml
    dir=$OUT/$name
    mkdir -p "$dir"
    echo "== $yaml"
    page=$dir/report.html

    # 1. the page
    if ! "$MECH" report "$yaml" --test-colours -o "$page"; then
        fail "mech report $yaml"
        continue
    fi
    xmllint --noout "$page" || fail "$page: not well-formed XML"
    "$MECH" solve "$yaml" -o "$dir/solve.csv" || fail "mech solve $yaml"
    points=$(sed -n 's/.*data-point="\([^"]*\)".*/\1/p' "$page" | paste -sd, -)
    "$MECH" solve "$yaml" --outputs "$points" --level positions -o "$dir/positions.csv" ||
        fail "mech solve $yaml --outputs $points"
    rows=$(($(wc -l <"$dir/solve.csv") - 1))

    # 2. the slider at K1 and K2
    for k in 0 $((rows / 3)); do
        url="file://$page#row=$k&test"
        browse "$url" 1400,1000 1 --virtual-time-budget=2000 --dump-dom >"$dir/dom$k.html" 2>"$dir/chromium.log" ||
            { cat "$dir/chromium.log"; fail "$name: chromium --dump-dom"; continue; }
        height=$(anim_bottom "$dir/dom$k.html")
        [ -n "$height" ] || { fail "$name: the page wrote no test report"; continue; }
        browse "$url" "1400,$height" 1 --screenshot="$dir/shot$k.png" >"$dir/chromium.log" 2>&1
        [ -s "$dir/shot$k.png" ] || { cat "$dir/chromium.log"; fail "$name: no screenshot"; continue; }
        echo "  slider at $k:"
        $CHECK slider "$dir/dom$k.html" "$dir/solve.csv" "$dir/positions.csv" $k \
            "$dir/shot$k.png" >"$dir/slider$k.txt" || fail "$name: slider at $k"
        grep -v '^moved ' "$dir/slider$k.txt"
    done
    $CHECK moved "$dir/slider0.txt" "$dir/slider$((rows / 3)).txt" 10 ||
        fail "$name: the drawing did not follow the slider"

    # Play: 1 s later the slider has followed the animation
    browse "file://$page#play&test" 1400,1000 1 --virtual-time-budget=4000 --dump-dom \
        >"$dir/dom-play.html" 2>"$dir/chromium.log" || fail "$name: chromium --dump-dom (play)"
    $CHECK play "$dir/dom-play.html" "$dir/solve.csv" "$rows" || fail "$name: Play"

    # 4. the whole page, every figure drawn
    nfig=$("$MECH" plot "$yaml" --out "$dir/plot" | wc -l)
    height=$(page_height "$dir/dom0.html")
    if [ -n "$height" ] && browse "file://$page" "1400,$height" 0.5 \
        --screenshot="$dir/page.png" >"$dir/chromium.log" 2>&1 && [ -s "$dir/page.png" ]; then
        echo "  the whole page (1400 x $height px at scale 0.5):"
        $CHECK figures "$dir/dom0.html" "$dir/page.png" 0.5 "$nfig" || fail "$name: figures"
    else
        cat "$dir/chromium.log"
        fail "$name: no screenshot of the whole page"
    fi
done

if [ "$fails" -ne 0 ]; then
    echo "tests/browser/report.sh: $fails failure(s); pages and screenshots in $OUT"
    exit 1
fi
echo "tests/browser/report.sh: all passed (pages and screenshots in $OUT)"
