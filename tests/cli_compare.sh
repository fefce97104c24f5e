#!/bin/sh
# tests/cli_compare.sh: `mech compare`: exit statuses, the verdict, the
# FILE:LINE:COLUMN of malformed files, --help (docs/cli.md, section mech compare).
# Run from the repository root:  MECH=build/mech sh tests/cli_compare.sh
# Prints one line per failure, then "cli-compare: N passed, M failed"; exits 1
# if anything failed.
NAME=cli-compare . tests/lib.sh

# expect LABEL FILE LINE: pass when FILE has the exact line LINE.
expect() {
    if grep -qxF -- "$3" "$2"; then
        pass
    else
        fail "$1: no line '$3' in $(basename "$2"): $(tail -n 1 "$2")"
    fi
}

# ---- the files -------------------------------------------------------------

cat >"$tmp/golden.csv" <<'EOF'
# mech solve fourbar.yaml
q [rad],B.x [m],B.vx [m/s]
0,100,0.5
0.1,100,-0.25
0.2,100,nan
EOF
cp "$tmp/golden.csv" "$tmp/same.csv"
# B.x of row 3 is 1.01e-7 away: just outside 1e-12 + 1e-9*100; an extra column
cat >"$tmp/near.csv" <<'EOF'
q [rad],B.x [m],B.vx [m/s],iterations [-]
0,100,0.5,3
0.1,100.000000099,-0.25,3
0.2,100.000000101,nan,4
EOF
printf 'q [rad],B.x [m],B.vx [m/s],iterations [-]\n0,100,0.5,3\n0.1,100,-0.25,3\n0.2,100,nan,4\n' >"$tmp/wide.csv"
printf 'q [rad],B.x [m],B.vx [m/s]\r\n0,100,0.5\r\n0.1,100,-0.25\r\n' >"$tmp/short.csv"
printf 'q [rad],B.x [mm],B.vx [m/s]\n0,100,0.5\n0.1,100,-0.25\n0.2,100,nan\n' >"$tmp/mm.csv"
printf 'q [rad],B.x [m],B.vx [m/s]\n0,100,0.5\n0.1,1OO,-0.25\n0.2,100\n' >"$tmp/bad.csv"

# ---- help and usage --------------------------------------------------------

if run "mech compare --help" 0 "$MECH" compare --help; then
    if grep -q '^usage: mech compare ' "$tmp/out" && grep -q '^options:' "$tmp/out" &&
        grep -q '^exit status:' "$tmp/out" && grep -q 'default 1e-9' "$tmp/out"; then
        pass
    else
        fail "mech compare --help: no usage line, options, defaults or exit status"
    fi
fi

if run "mech help compare" 0 "$MECH" help compare; then
    if grep -q '^usage: mech compare ' "$tmp/out"; then
        pass
    else
        fail "mech help compare: no 'usage: mech compare' line"
    fi
fi

if run "mech --help" 0 "$MECH" --help; then
    if grep -q '^  compare ' "$tmp/out"; then
        pass
    else
        fail "mech --help: compare is not listed"
    fi
fi

run "mech compare (no files)" 2 "$MECH" compare && pass
run "mech compare (one file)" 2 "$MECH" compare "$tmp/same.csv" && pass
run "mech compare (three files)" 2 "$MECH" compare "$tmp/same.csv" "$tmp/same.csv" "$tmp/same.csv" && pass
run "mech compare --frob" 2 "$MECH" compare --frob "$tmp/same.csv" "$tmp/golden.csv" && pass
run "mech compare --rtol -1" 2 "$MECH" compare --rtol -1 "$tmp/same.csv" "$tmp/golden.csv" && pass
run "mech compare --atol x" 2 "$MECH" compare --atol x "$tmp/same.csv" "$tmp/golden.csv" && pass
run "mech compare --rtol (no value)" 2 "$MECH" compare "$tmp/same.csv" "$tmp/golden.csv" --rtol && pass

# ---- 0: the files match ------------------------------------------------------

if run "identical" 0 "$MECH" compare "$tmp/same.csv" "$tmp/golden.csv"; then
    expect "identical" "$tmp/out" "compare: 3 columns, 3 rows: all within rtol 1e-09 atol 1e-12"
fi

if run "--rtol 1e-8" 0 "$MECH" compare --rtol 1e-8 "$tmp/near.csv" "$tmp/golden.csv"; then
    expect "--rtol 1e-8" "$tmp/out" "extra in OUT (not compared): iterations [-]"
fi

run "--atol=2e-7" 0 "$MECH" compare --atol=2e-7 "$tmp/near.csv" "$tmp/golden.csv" && pass

if run "--columns q,B.vx" 0 "$MECH" compare --columns q,B.vx "$tmp/near.csv" "$tmp/golden.csv"; then
    if grep -q '^B\.x ' "$tmp/out"; then
        fail "--columns q,B.vx: B.x is compared"
    else
        pass
    fi
fi

# ---- 1: the files differ -----------------------------------------------------

if run "just outside rtol" 1 "$MECH" compare "$tmp/near.csv" "$tmp/golden.csv"; then
    expect "just outside rtol" "$tmp/out" \
        "compare: 1 of 3 columns differs (first: B.x at row 3: 100.000000101 vs 100)"
    if grep -q '^B\.x  *m  .*  3  FAIL$' "$tmp/out"; then
        pass
    else
        fail "just outside rtol: B.x line: $(grep '^B\.x ' "$tmp/out")"
    fi
fi

if run "row counts" 1 "$MECH" compare "$tmp/short.csv" "$tmp/golden.csv"; then
    if grep -q '^compare: row counts differ: OUT has 2 rows, GOLDEN has 3' "$tmp/out"; then
        pass
    else
        fail "row counts: verdict $(tail -n 1 "$tmp/out")"
    fi
fi

if run "unit" 1 "$MECH" compare "$tmp/mm.csv" "$tmp/golden.csv"; then
    if grep -q '^B\.x .*FAIL (unit \[mm\] in OUT)$' "$tmp/out"; then
        pass
    else
        fail "unit: B.x line: $(grep '^B\.x ' "$tmp/out")"
    fi
fi

if run "missing column" 1 "$MECH" compare "$tmp/golden.csv" "$tmp/wide.csv"; then
    expect "missing column" "$tmp/out" "compare: 1 of 4 columns differs (first: iterations missing from OUT)"
fi

# ---- 2: malformed files, bad --columns ---------------------------------------

if run "malformed" 2 "$MECH" compare "$tmp/bad.csv" "$tmp/golden.csv"; then
    expect "malformed" "$tmp/err" "$tmp/bad.csv:3:5: error: '1OO' in column 'B.x' is not a number"
    expect "malformed" "$tmp/err" \
        "$tmp/bad.csv:4:8: error: row has 2 fields, expected 3 as in the header (line 1)"
    if [ -s "$tmp/out" ]; then
        fail "malformed: something on stdout: $(head -n 1 "$tmp/out")"
    else
        pass
    fi
fi

if run "--columns B.vy" 2 "$MECH" compare --columns B.vy "$tmp/same.csv" "$tmp/golden.csv"; then
    expect "--columns B.vy" "$tmp/err" \
        "$tmp/golden.csv: error: --columns: no column 'B.vy' (did you mean 'B.vx'?)"
fi

# ---- 3: unreadable files -------------------------------------------------------

if run "missing file" 3 "$MECH" compare "$tmp/none.csv" "$tmp/golden.csv"; then
    if grep -q "^$tmp/none.csv: error: cannot open" "$tmp/err"; then
        pass
    else
        fail "missing file: the message does not name the file: $(head -n 1 "$tmp/err")"
    fi
fi

run "directory" 3 "$MECH" compare "$tmp/same.csv" "$tmp" && pass

# ---- a solver round trip, when `mech solve` exists -------------------------------

if "$MECH" solve --help >/dev/null 2>&1 && [ -f mechanisms/fourbar.yaml ]; then
    if "$MECH" solve mechanisms/fourbar.yaml -o "$tmp/a.csv" 2>"$tmp/err" &&
        "$MECH" solve mechanisms/fourbar.yaml -o "$tmp/b.csv" 2>"$tmp/err"; then
        run "solve twice, compare" 0 "$MECH" compare "$tmp/a.csv" "$tmp/b.csv" && pass
    else
        fail "mech solve mechanisms/fourbar.yaml: $(head -n 1 "$tmp/err")"
    fi
    # a golden kept in the file's units (mm, deg): the SI golden with each
    # column scaled by its unit, by awk; `--units file` writes the same
    awk -F, -v OFS=, 'NR == 1 { for (i = 1; i <= NF; i++) { f[i] = 1; u = $i
                                   if (u ~ /\[m(\/|\])/) { f[i] = 1000; sub(/\[m/, "[mm", $i) }
                                   if (u ~ /\[rad/) { f[i] = 180 / 3.14159265358979324; sub(/\[rad/, "[deg", $i) } }
                        print; next }
                      { for (i = 1; i <= NF; i++) $i = sprintf("%.17g", $i * f[i]); print }' \
        tests/golden/fourbar.csv >"$tmp/golden-mm.csv"
    has_line "$tmp/golden-mm.csv" "^q \[deg\],A.x \[mm\],A.y \[mm\],A.vx \[mm/s\],A.vy \[mm/s\],A.ax \[mm/s^2\]" "golden in mm: header"
    if run "solve --units file" 0 "$MECH" solve mechanisms/fourbar.yaml --units file -o "$tmp/mm.csv"; then
        run "--units file against a golden in mm and deg" 0 "$MECH" compare "$tmp/mm.csv" "$tmp/golden-mm.csv" && pass
        run "SI against a golden in mm and deg" 1 "$MECH" compare "$tmp/a.csv" "$tmp/golden-mm.csv" && pass
    fi
    # --stats and the --tolerances summary in the file's units
    if run "solve --units file --stats --tolerances" 0 "$MECH" solve tests/sweep/tol-slider-crank.yaml \
        --units file --stats --tolerances -o "$tmp/tol.csv"; then
        has_line "$tmp/err" "from r +-0.05 mm l +-0.1 mm" "--tolerances: the parameters' tolerances in mm"
        has_line "$tmp/err" "worst residual .* mm$" "--stats: the residual in mm"
        has_line "$tmp/err" "^  B.x .*\[mm\] (worst at q = 240)" "--tolerances: worst(B.x) in mm, q in deg"
        has_line "$tmp/tol.csv" "worst(B.x) \[mm\]" "--tolerances: the column in mm"
    fi
fi


# ---- HDF5 outputs (docs/cli.md, HDF5 output) ---------------------------------
# the same numbers as the CSV, read by mech compare on either side with a zero
# tolerance; written whole; a symbolic link's target; a FIFO; never an input;
# an HDF5 file that is not mech's, and one cut short, are errors
if run "solve -o run.h5" 0 "$MECH" solve mechanisms/fourbar.yaml --forces -o "$tmp/run.h5" &&
   run "solve -o run.csv" 0 "$MECH" solve mechanisms/fourbar.yaml --forces -o "$tmp/run.csv"; then
    run "HDF5 against the CSV, exactly" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/run.h5" "$tmp/run.csv" && pass
    run "the CSV against HDF5, exactly" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/run.csv" "$tmp/run.h5" && pass
    has_line "$tmp/out" "^compare: 42 columns, 361 rows: all within" "HDF5: every column and row read"
    [ "$(head -c 4 "$tmp/run.h5" | od -An -c | tr -d ' ')" = "211HDF" ] && pass || fail "run.h5 has no HDF5 signature"
    ls "$tmp"/run.h5.tmp* >/dev/null 2>&1 && fail "a temporary file was left beside run.h5" || pass
    cp "$tmp/run.h5" "$tmp/target.h5"
    ln -s "$tmp/target.h5" "$tmp/link.h5"
    if run "solve -o LINK.h5" 0 "$MECH" solve mechanisms/slider-crank.yaml -o "$tmp/link.h5"; then
        [ -L "$tmp/link.h5" ] && pass || fail "the symbolic link was replaced"
        "$MECH" solve mechanisms/slider-crank.yaml -o "$tmp/sc.csv" 2>/dev/null
        run "the link's target holds the new run" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/target.h5" "$tmp/sc.csv" && pass
    fi
    if mkfifo "$tmp/pipe.h5" 2>/dev/null; then
        cat "$tmp/pipe.h5" >"$tmp/from-pipe.h5" &
        run "solve -o FIFO.h5" 0 "$MECH" solve mechanisms/fourbar.yaml --forces -o "$tmp/pipe.h5"
        wait
        run "what came through the FIFO" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/from-pipe.h5" "$tmp/run.csv" && pass
    fi
    run "simulate -o run.h5" 0 "$MECH" simulate tests/dynamics/pendulum.yaml --to 0.2 -o "$tmp/sim.h5" &&
        run "simulate: HDF5 against CSV" 0 "$MECH" simulate tests/dynamics/pendulum.yaml --to 0.2 -o "$tmp/sim.csv" &&
        run "simulate: the same numbers" 0 "$MECH" compare --rtol 0 --atol 0 "$tmp/sim.h5" "$tmp/sim.csv" && pass
    head -c 2000 "$tmp/run.h5" >"$tmp/cut.h5"
    run "an HDF5 file cut short" 3 "$MECH" compare "$tmp/cut.h5" "$tmp/run.csv" &&
        has_line "$tmp/err" "cut.h5: error: cannot open the HDF5 file" "the cut file is named"
    cp mechanisms/fourbar.yaml "$tmp/in.h5"
    run "the output is the input" 2 "$MECH" solve "$tmp/in.h5" -o "$tmp/in.h5" &&
        cmp -s "$tmp/in.h5" mechanisms/fourbar.yaml && pass
fi

summary
