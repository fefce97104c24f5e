#!/bin/sh
# tests/drawn.sh: the drawn form and point guesses (docs/format.md 5.4, 8.1).
# Run from the repository root:  MECH=build/mech sh tests/drawn.sh
# Every drawn file of tests/drawn/ is solved and its rows checked against
# its construction by circle and line intersections (tests/drawn/truth.py,
# independent of mech); the same mechanism in the local form gives the same
# table; parameters named in the drawing move the derived geometry; point
# guesses choose the assembly, and a guess that cannot act is warned about.
NAME=drawn . tests/lib.sh

# ---- every drawn file assembles as drawn, over its whole sweep -----------

for f in tests/drawn/*.yaml; do
    grep -q '^# truth:' "$f" || continue  # fourbar-params.yaml: below
    run "mech solve $f" 0 "$MECH" solve "$f" -o "$tmp/rows.csv" || continue
    if python3 tests/drawn/truth.py "$f" "$tmp/rows.csv" >"$tmp/truth" 2>&1; then
        pass
    else
        fail "$f: $(head -n 1 "$tmp/truth")"
    fi
    if [ -s "$tmp/err" ]; then
        fail "$f: mech solve wrote to stderr: $(head -n 1 "$tmp/err")"
    fi
done

# ---- a range that starts where the mechanism does not assemble: the drawn
#      assembly is followed from the drawing until it stops (reported), the
#      rows after the gap are still the drawn assembly

sed -e 's/from: -40, to: 200, steps: 48/from: -60, to: 200, steps: 52/' tests/drawn/stephenson.yaml >"$tmp/partial.yaml"
if run "solve a range starting outside the assembly" 1 "$MECH" solve "$tmp/partial.yaml" -o "$tmp/partial.csv"; then
    has_line "$tmp/err" "error: the drawn assembly, followed from the drawing's driver value 60 deg towards the sweep's first value -60 deg, stops at -43.876 deg" "the way from the drawing stops"
    if python3 tests/drawn/truth.py "$tmp/partial.yaml" "$tmp/partial.csv" >"$tmp/truth" 2>&1; then
        pass
    else
        fail "the rows after the gap: $(head -n 1 "$tmp/truth")"
    fi
fi

# ---- the same mechanism in both forms: the same table ---------------------
# The local file's lengths are the drawing's to 17 digits, so the tables
# agree to rounding (1e-12 absolute, SI).

if run "solve the local four-bar" 0 "$MECH" solve tests/drawn/local/fourbar.yaml -o "$tmp/local.csv" &&
   run "solve the drawn four-bar" 0 "$MECH" solve tests/drawn/fourbar.yaml -o "$tmp/drawn.csv"; then
    if run "compare the two forms" 0 "$MECH" compare --rtol 0 --atol 1e-12 "$tmp/drawn.csv" "$tmp/local.csv"; then
        pass
    fi
fi

# ---- the issue's toggle press: the local form without guesses folds the
#      ram onto F; point guesses (or the drawing) assemble it as drawn -----

if run "solve the local toggle press" 0 "$MECH" solve tests/drawn/local/toggle-press.yaml -o "$tmp/folded.csv"; then
    if python3 tests/drawn/truth.py tests/drawn/toggle-press.yaml "$tmp/folded.csv" >/dev/null; then
        fail "the local toggle press without guesses no longer folds: this test's premise is gone"
    else
        pass
    fi
fi
if run "solve the toggle press with point guesses" 0 "$MECH" solve tests/drawn/local/toggle-press-guessed.yaml -o "$tmp/guessed.csv" &&
   run "solve the drawn toggle press" 0 "$MECH" solve tests/drawn/toggle-press.yaml -o "$tmp/drawn.csv"; then
    # the drawn lengths are 15, 60, 50 mm to about 1e-12: compare to 1e-9
    if run "point guesses give the drawn press" 0 "$MECH" compare --rtol 1e-9 --atol 1e-9 "$tmp/guessed.csv" "$tmp/drawn.csv"; then
        pass
    fi
fi

# ---- a point guess chooses the branch: B above AC is the open four-bar,
#      B below it the crossed one (without guesses the solver finds the
#      crossed one, so the first case fails when point guesses do nothing)

for case in "62, 50:fourbar.yaml" "40, -40:fourbar-crossed.yaml"; do
    xy=${case%%:*} truth=tests/drawn/${case#*:}
    sed -e "s/^initial: .*/initial: {B: [$xy]}/" tests/drawn/local/fourbar.yaml >"$tmp/guess.yaml"
    run "solve the four-bar with B guessed at [$xy]" 0 "$MECH" solve "$tmp/guess.yaml" -o "$tmp/guess.csv" || continue
    grep -v '^# truth: rigid P A B$' "$truth" >"$tmp/truth.yaml"
    if python3 tests/drawn/truth.py "$tmp/truth.yaml" "$tmp/guess.csv" >"$tmp/truth" 2>&1; then
        pass
    else
        fail "point guess B: [$xy]: $(head -n 1 "$tmp/truth")"
    fi
done

# ---- guesses that cannot act are warned about, at the guess ---------------

sed -e 's/^initial: .*/initial: {O: [1, 1], A: [0, 20]}/' tests/drawn/local/fourbar.yaml >"$tmp/useless.yaml"
if run "check useless point guesses" 0 "$MECH" check "$tmp/useless.yaml"; then
    has_line "$tmp/err" "useless.yaml:13:11: warning: the initial guess for point 'O' has no effect: 'O' is a point of the ground, which does not move" "a guess on the ground"
    has_line "$tmp/err" "useless.yaml:13:22: warning: the initial guess for point 'A' has no effect: the ground, the driver and the other guesses already place it" "a guess on the driven crank"
fi
sed -e 's/^initial: .*/initial: {B: [62, 50], P: [30, 60]}/' tests/drawn/local/fourbar.yaml >"$tmp/redundant.yaml"
if run "check a redundant point guess" 0 "$MECH" check "$tmp/redundant.yaml"; then
    has_line "$tmp/err" "redundant.yaml:13:24: warning: the initial guess for point 'P' has no effect: the links that carry it have their angles from the driver or the other guesses" "a redundant guess"
    if [ "$(grep -c warning "$tmp/err")" -ne 1 ]; then
        fail "a redundant guess: $(grep -c warning "$tmp/err") warnings, expected the one for P"
    fi
fi
sed -e 's/^initial: .*/initial: {P: [30, 60]}/' tests/drawn/local/fourbar.yaml >"$tmp/useful.yaml"
if run "check a useful point guess" 0 "$MECH" check "$tmp/useful.yaml"; then
    if grep -q warning "$tmp/err"; then
        fail "a useful point guess warned about: $(head -n 1 "$tmp/err")"
    else
        pass
    fi
fi
sed -e 's/^springs:/initial: {ram: 10}\nsprings:/' tests/drawn/local/toggle-press.yaml >"$tmp/block.yaml"
if run "check a guess for a locked block" 0 "$MECH" check "$tmp/block.yaml"; then
    has_line "$tmp/err" "warning: the initial guess for 'ram' has no effect: a block on a locked slider turns with its guide" "a locked block's angle"
fi

# ---- parameters named in the drawing move the derived geometry ----------

f=tests/drawn/fourbar-params.yaml
sed -e 's/C: \[d, 0\]/C: [75, 0]/' "$f" >"$tmp/d75.yaml"
if run "solve with --set d=75mm" 0 "$MECH" solve --set d=75mm "$f" -o "$tmp/set.csv" &&
   run "solve with C drawn at 75" 0 "$MECH" solve "$tmp/d75.yaml" -o "$tmp/d75.csv"; then
    if run "--set d moves the drawn pivot" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/set.csv" "$tmp/d75.csv"; then
        pass
    fi
fi
if run "sweep --vary d" 0 "$MECH" sweep "$f" --vary d=70mm:75mm:2 --metric max:B.x -o "$tmp/sweep.csv"; then
    want=$(python3 -c "
import csv
r = list(csv.reader(open('$tmp/d75.csv')))
i = [h.split(' [')[0] for h in r[0]].index('B.x')
print(repr(max(float(x[i]) for x in r[1:])))")
    got=$(sed -n '3p' "$tmp/sweep.csv" | awk -F, '{print $NF}')
    if python3 -c "import sys; sys.exit(abs($got - $want) > 1e-15)"; then
        pass
    else
        fail "sweep --vary d=75mm: max B.x $got, the file with C at 75 mm gives $want"
    fi
fi

# the derivative --sensitivity gives against a central difference of --set
if run "solve --sensitivity d" 0 "$MECH" solve "$f" --sensitivity d -o "$tmp/sens.csv" &&
   run "solve d - 0.1 um" 0 "$MECH" solve --set "d=69.9999 mm" "$f" -o "$tmp/lo.csv" &&
   run "solve d + 0.1 um" 0 "$MECH" solve --set "d=70.0001 mm" "$f" -o "$tmp/hi.csv"; then
    if python3 - "$tmp" <<'PY'
import csv, sys
def rows(name):
    r = list(csv.reader(open(sys.argv[1] + "/" + name)))
    return [h.split(" [")[0] for h in r[0]], r[1:]
h, s = rows("sens.csv")
hl, lo = rows("lo.csv")
_, hi = rows("hi.csv")
d, b = h.index("d(B.x)/d(d)"), hl.index("B.x")
for k in range(len(s)):
    fd = (float(hi[k][b]) - float(lo[k][b])) / 2e-7
    if abs(float(s[k][d]) - fd) > 1e-6 * (1 + abs(fd)):
        print("row %d: d(B.x)/d(d) %s, central difference %.9g" % (k, s[k][d], fd))
        sys.exit(1)
PY
    then pass; else fail "--sensitivity d of a drawn parameter differs from the central difference"; fi
fi

# ---- mech convert: each form written from the other gives the same table.
# The numbers are written to 15 digits in the file's units, so the tables
# agree to rounding (1e-12 relative and absolute, SI).

same_table() {  # same_table LABEL A.yaml B.yaml
    run "$1: solve $2" 0 "$MECH" solve "$2" -o "$tmp/a.csv" &&
    run "$1: solve $3" 0 "$MECH" solve "$3" -o "$tmp/b.csv" &&
    run "$1: the same table" 0 "$MECH" compare --rtol 1e-12 --atol 1e-12 "$tmp/a.csv" "$tmp/b.csv" &&
    pass
}

for f in tests/drawn/*.yaml; do
    grep -q '^# truth:' "$f" || continue
    run "mech convert $f" 0 "$MECH" convert "$f" -o "$tmp/local.yaml" || continue
    if grep -q '^drawing:' "$tmp/local.yaml" || ! grep -q '^initial:' "$tmp/local.yaml"; then
        fail "mech convert $f: the local form has a drawing or no initial guesses"
    fi
    same_table "drawn -> local" "$tmp/local.yaml" "$f"
done
# comments outside the rewritten sections are kept
has_line "$tmp/local.yaml" "^# truth: crank A O2$" "mech convert keeps the comments above the sections"

full_list=$(ls mechanisms/*.yaml)
[ -n "${MECH_QUICK:-}" ] && full_list="mechanisms/fourbar.yaml mechanisms/shaper.yaml mechanisms/epicyclic.yaml"
for f in $full_list; do
    run "mech convert $f" 0 "$MECH" convert "$f" -o "$tmp/drawn.yaml" || continue
    if grep -q 'warning: link' "$tmp/err"; then
        continue  # a frame not along two points: its angle column differs (below)
    fi
    same_table "local -> drawn" "$tmp/drawn.yaml" "$f"
    run "mech convert back" 0 "$MECH" convert "$tmp/drawn.yaml" -o "$tmp/back.yaml" &&
        same_table "local -> drawn -> local" "$tmp/back.yaml" "$f"
done
if run "mech convert the conveyor" 0 "$MECH" convert mechanisms/conveyor.yaml -o "$tmp/drawn.yaml"; then
    has_line "$tmp/err" "warning: link 'tray' has no point at its frame's origin with another on its x axis" "a frame not along two points"
fi
run "mech convert --to local a local file" 0 "$MECH" convert --to local mechanisms/fourbar.yaml -o "$tmp/same.yaml" &&
    if cmp -s "$tmp/same.yaml" mechanisms/fourbar.yaml; then pass; else fail "mech convert --to local changed a local file"; fi

# mech draw of a drawn file: the mechanism at the drawing's driver value
# (45 deg for the four-bar), where it assembles as drawn: no dashed pose
if run "mech draw a drawn file" 0 "$MECH" draw tests/drawn/fourbar.yaml -o "$tmp/pose.svg"; then
    if grep -q "crank at 45 deg (the drawing's position)" "$tmp/pose.svg"; then pass
    else fail "mech draw: the caption does not say the drawing's position (45 deg)"; fi
    if grep -q "assembled away" "$tmp/err"; then fail "mech draw: a drawn four-bar assembled away from its drawing"
    else pass; fi
fi

# the assembly checks (docs/solver.md section 9) hold a drawn file's
# assembly to its drawing, where its guesses hold, not to the sweep's first
# row: every drawn file is silent under --strict
for f in tests/drawn/*.yaml; do
    run "mech solve --strict $f" 0 "$MECH" solve --strict "$f" -o "$tmp/strict.csv" &&
        if grep -q warning "$tmp/err"; then fail "$f: $(grep warning "$tmp/err" | head -n 1)"
        else pass; fi
done

summary
