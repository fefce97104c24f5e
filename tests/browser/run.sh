#!/bin/sh
# tests/browser/run.sh: `mech plot` and `mech animate` seen in a browser.
#
# For mechanisms/stirling.yaml and mechanisms/conveyor.yaml:
#   1. every figure of `mech plot` and the animation of `mech animate` are
#      well-formed XML (xmllint --noout) and render to a non-blank screenshot
#      in headless chromium (no network: no proxy, every host unresolvable);
#   2. still frames K1 and K2 (`--frame K --test-colours`: every point a disc
#      of its own colour): each disc's pixel centroid, mapped back through
#      the SVG's data-mech-transform, is within 2 px of the point's position
#      in row K of `mech solve --outputs <all points> --level positions`;
#   3. the ordinary still frames K1 and K2 differ around every point that
#      moved and are the same far from the mechanism;
#   4. the animation itself (SMIL), stopped at 1 s and 2 s of its 4 s cycle
#      (`--pause-at T` adds an inline script that pauses it there): the discs
#      are those of rows (N-1)/4 and (N-1)/2 of the sweep within 3 px; and,
#      left playing for 2 s of virtual time, the picture is a solved position;
#   5. every path figure (path-P.svg): the curve's pixels lie within 1.5 px of
#      the solved positions of P mapped through data-mech-transform, and every
#      solved position has a curve pixel within 1.5 px;
#   6. a 20 000-step path figure, thinned to within 0.25 px: the same check
#      against all 20 001 solved positions;
#   7. the animation's scale bar is drawn as long as its label says.
#
# Needs (Debian): chromium, libxml2-utils (xmllint), python3 (standard
# library only: tests/browser/pngcheck.py decodes the PNGs), fonts-dejavu-core.
# usage: MECH=build/mech sh tests/browser/run.sh   (writes into $OUT, default build/browser)
set -u
cd "$(dirname "$0")/../.."   # the repository root: MECH and OUT are relative to it
MECH=${MECH:-build/mech}
OUT=${OUT:-build/browser}
CHROMIUM=${CHROMIUM:-chromium}
CHECK="python3 tests/browser/pngcheck.py"
. tests/browser/lib.sh

# svg_size FILE -> "W,H" from the root element's width and height
svg_size() {
    sed -n 's/.*<svg [^>]*width="\([0-9]*\)" height="\([0-9]*\)".*/\1,\2/p' "$1" | head -n 1
}

# shot SVG PNG [VIRTUAL_MS]: a screenshot at the SVG's own size
shot() {
    size=$(svg_size "$1")
    budget=""
    [ $# -ge 3 ] && budget="--virtual-time-budget=$3"
    browse "file://$1" "$size" 1 $budget --screenshot="$2" >"$OUT/chromium.log" 2>&1
    [ -s "$2" ] || { cat "$OUT/chromium.log"; return 1; }
}

for name in stirling conveyor; do
    yaml=mechanisms/$name.yaml
    dir=$OUT/$name
    mkdir -p "$dir"
    echo "== $yaml"

    # 1. the figures
    if ! "$MECH" plot "$yaml" --out "$dir" >"$dir/figures.txt"; then
        fail "mech plot $yaml"
        continue
    fi
    nfig=$(wc -l <"$dir/figures.txt")
    [ "$nfig" -ge 6 ] || fail "$yaml: only $nfig figures"
    while read -r svg; do
        xmllint --noout "$svg" || fail "$svg: not well-formed XML"
        png=${svg%.svg}.png
        if shot "$svg" "$png"; then
            $CHECK blank "$png" || fail "$svg renders blank"
        else
            fail "$svg: no screenshot"
        fi
    done <"$dir/figures.txt"
    echo "  $nfig figures: well-formed, rendered"

    # the animation, the solved positions of every point
    "$MECH" animate "$yaml" -o "$dir/anim.svg" || fail "mech animate $yaml"
    "$MECH" animate "$yaml" --test-colours -o "$dir/anim-test.svg" || fail "mech animate --test-colours $yaml"
    for f in anim anim-test; do
        xmllint --noout "$dir/$f.svg" || fail "$dir/$f.svg: not well-formed XML"
    done
    shot "$dir/anim.svg" "$dir/anim.png" && $CHECK blank "$dir/anim.png" || fail "$name: animation renders blank"
    points=$(sed -n 's/.*data-point="\([^"]*\)".*/\1/p' "$dir/anim-test.svg" | paste -sd, -)
    "$MECH" solve "$yaml" --outputs "$points" --level positions -o "$dir/positions.csv" ||
        fail "mech solve $yaml --outputs $points"
    rows=$(($(wc -l <"$dir/positions.csv") - 1))
    k1=0
    k2=$((rows / 4))

    # 2. still frames: the discs where the solver put the points
    for k in $k1 $k2; do
        "$MECH" animate "$yaml" --frame $k --test-colours -o "$dir/frame$k-test.svg" &&
            xmllint --noout "$dir/frame$k-test.svg" &&
            shot "$dir/frame$k-test.svg" "$dir/frame$k-test.png" || fail "$name frame $k"
        echo "  frame $k (--test-colours) against row $k of positions.csv:"
        $CHECK joints "$dir/frame$k-test.png" "$dir/frame$k-test.svg" "$dir/positions.csv" $k ||
            fail "$name frame $k: points drawn away from their solved positions"
    done

    # 3. the ordinary frames differ where the mechanism moved
    for k in $k1 $k2; do
        "$MECH" animate "$yaml" --frame $k -o "$dir/frame$k.svg" &&
            xmllint --noout "$dir/frame$k.svg" && shot "$dir/frame$k.svg" "$dir/frame$k.png" ||
            fail "$name frame $k"
    done
    echo "  frames $k1 and $k2 differ where the points moved:"
    $CHECK moved "$dir/frame$k1.png" "$dir/frame$k2.png" "$dir/frame$k1-test.svg" \
        "$dir/positions.csv" $k1 $k2 || fail "$name: frames $k1 and $k2"

    # 4. the animation itself: stopped at 1 s and 2 s of its 4 s cycle by
    #    --pause-at (an inline script: pauseAnimations, setCurrentTime), the
    #    SMIL-interpolated picture must be rows (rows-1)/4 and (rows-1)/2
    for t in 1 2; do
        want=$(((rows - 1) * t / 4))
        "$MECH" animate "$yaml" --test-colours --pause-at $t -o "$dir/anim-at$t.svg" &&
            xmllint --noout "$dir/anim-at$t.svg" && shot "$dir/anim-at$t.svg" "$dir/anim-at$t.png" ||
            fail "$name: animation paused at $t s"
        echo "  animation paused at $t s (row $want expected):"
        $CHECK fit "$dir/anim-at$t.png" "$dir/anim-at$t.svg" "$dir/positions.csv" >"$dir/fit-at$t.txt" ||
            fail "$name: the animation at $t s is not a solved position"
        sed -n '/best row/p' "$dir/fit-at$t.txt"
        got=$(sed -n 's/^row //p' "$dir/fit-at$t.txt")
        [ "$got" = "$want" ] || fail "$name: the animation at $t s shows row $got, not row $want"
    done
    #    and it plays on its own: after 2 s of virtual time the picture is a
    #    solved position (which one depends on how long loading took)
    if shot "$dir/anim-test.svg" "$dir/anim-playing.png" 2000; then
        echo "  animation playing, 2000 ms of virtual time:"
        $CHECK fit "$dir/anim-playing.png" "$dir/anim-test.svg" "$dir/positions.csv" >"$dir/fit-playing.txt" ||
            fail "$name: the playing animation is not a solved position"
        sed -n '/best row/p' "$dir/fit-playing.txt"
    else
        fail "$name: no screenshot of the playing animation"
    fi

    # 5. the path figures: curve pixels where the solved positions map
    for svg in $(grep -- '-path-' "$dir/figures.txt"); do
        point=${svg##*-path-}
        point=${point%.svg}
        echo "  path of $point ($(basename "$svg")) against positions.csv:"
        $CHECK path "${svg%.svg}.png" "$svg" "$dir/positions.csv" "$point" ||
            fail "$name: the path of $point is not drawn where it was solved"
    done
    npath=$(grep -c -- '-path-' "$dir/figures.txt")
    [ "$npath" -ge 1 ] || fail "$name: no path figure"

    # 6. a long sweep's path, thinned, against every solved position
    point=$(grep -- '-path-' "$dir/figures.txt" | head -n 1)
    point=${point##*-path-}
    point=${point%.svg}
    long=$dir/long
    if "$MECH" plot "$yaml" --steps 20000 --outputs "$point" --out "$long" >/dev/null &&
        "$MECH" solve "$yaml" --steps 20000 --outputs "$point" --level positions -o "$long/positions.csv" &&
        shot "$long/$name-path-$point.svg" "$long/path.png"; then
        nv=$(sed -n 's/.*<path stroke="#1f4e99" d="\([^"]*\)".*/\1/p' "$long/$name-path-$point.svg" | tr -cd , | wc -c)
        echo "  path of $point over 20 000 steps, $nv vertices drawn, against its 20 001 positions:"
        [ "$nv" -gt 1 ] && [ "$nv" -lt 4032 ] || fail "$name: the 20 000-step path has $nv vertices"
        $CHECK path "$long/path.png" "$long/$name-path-$point.svg" "$long/positions.csv" "$point" ||
            fail "$name: the thinned path is not where the solved positions are"
    else
        fail "$name: the 20 000-step path figure"
    fi

    # 7. the scale bar (the --test-colours still of step 2)
    $CHECK scalebar "$dir/frame$k1-test.png" "$dir/frame$k1-test.svg" ||
        fail "$name: the scale bar is not as long as its label"
done

if [ "$fails" -ne 0 ]; then
    echo "tests/browser: $fails failure(s); screenshots in $OUT"
    exit 1
fi
echo "tests/browser: all passed (screenshots in $OUT)"
