#!/bin/sh
# tests/cli.sh: the `mech` command line: exit statuses and what it prints.
# Run from the repository root:  MECH=build/mech sh tests/cli.sh
# Prints one line per failure, then "cli: N passed, M failed"; exits 1 if
# anything failed. MECH_QUICK=1: all but the plot of 10^6 steps.
NAME=cli . tests/lib.sh

# ---- usage ----------------------------------------------------------------

if run "mech --help" 0 "$MECH" --help; then
    if grep -q '^commands:' "$tmp/out" && grep -q '^  check ' "$tmp/out"; then
        pass
    else
        fail "mech --help: the output does not list the commands (no 'commands:' and 'check')"
    fi
fi

if run "mech --version" 0 "$MECH" --version; then
    if grep -q '^mech [0-9][0-9.]*' "$tmp/out"; then
        pass
    else
        fail "mech --version: prints '$(head -n 1 "$tmp/out")', expected 'mech VERSION'"
    fi
fi

if run "mech check --help" 0 "$MECH" check --help; then
    if grep -q '^usage: mech check' "$tmp/out"; then
        pass
    else
        fail "mech check --help: no 'usage: mech check' line"
    fi
fi

if run "mech (no command)" 2 "$MECH"; then
    if grep -q '^usage: mech' "$tmp/err"; then
        pass
    else
        fail "mech (no command): no usage on stderr"
    fi
fi

if run "mech frobnicate" 2 "$MECH" frobnicate; then
    if grep -q "frobnicate" "$tmp/err"; then
        pass
    else
        fail "mech frobnicate: the message does not name the unknown command"
    fi
fi

if run "mech check (no file)" 2 "$MECH" check; then
    if [ -s "$tmp/err" ]; then
        pass
    else
        fail "mech check (no file): nothing on stderr"
    fi
fi

missing=tests/no-such-mechanism.yaml
if run "mech check $missing" 3 "$MECH" check "$missing"; then
    if grep -q "$missing" "$tmp/err"; then
        pass
    else
        fail "mech check $missing: the message does not name the file: $(head -n 1 "$tmp/err")"
    fi
fi

# ---- input files that are not regular, or too large (issue 16 item 11d):
#      refused from fstat before reading, so a FIFO cannot hang `check` ----

# without timeout(1) a regression would hang here instead of failing
limit=""
command -v timeout >/dev/null 2>&1 && limit="timeout 20"
if mkfifo "$tmp/fifo.yaml" 2>/dev/null; then
    if run "mech check FIFO" 3 $limit "$MECH" check "$tmp/fifo.yaml"; then
        has_line "$tmp/err" "fifo.yaml: error: cannot read: a FIFO (named pipe), not a regular file" "check: FIFO refused"
    fi
fi
mkdir "$tmp/dir.yaml"
if run "mech check directory" 3 "$MECH" check "$tmp/dir.yaml"; then
    has_line "$tmp/err" "dir.yaml: error: cannot read: a directory, not a regular file" "check: directory refused"
fi
if run "mech solve directory" 3 "$MECH" solve "$tmp/dir.yaml" -o "$tmp/dir.csv"; then
    has_line "$tmp/err" "dir.yaml: error: cannot read: a directory, not a regular file" "solve: directory refused"
fi
# one byte over 32 MiB, sparse: refused from its size, not after reading it
if truncate -s 33554433 "$tmp/big.yaml" 2>/dev/null; then
    if run "mech check 32 MiB + 1" 2 "$MECH" check "$tmp/big.yaml"; then
        has_line "$tmp/err" "big.yaml: error: file too large (33554433 bytes; at most 33554432)" "check: size from fstat"
    fi
    rm -f "$tmp/big.yaml"
fi

# ---- malformed files: status 2, and the first diagnostic is the first
#      '# expect:' line of the file, prefixed with the file name --------------

for f in tests/bad/*.yaml; do
    [ -e "$f" ] || { fail "no files in tests/bad"; break; }
    first=$(sed -n 's/^# expect: //p' "$f" | head -n 1)
    if [ -z "$first" ]; then
        fail "$f: no '# expect:' line"
        continue
    fi
    run "mech check $f" 2 "$MECH" check "$f" || continue
    got=$(head -n 1 "$tmp/err")
    case $first in
    *": error: "*) ;;
    *) fail "$f: the first expectation is not an error: $first"; continue ;;
    esac
    if [ "$got" = "$f:$first" ]; then
        pass
    else
        fail "$f: first line of stderr is '$got', expected '$f:$first'"
    fi
done

# ---- the example mechanisms are valid -----------------------------------

for f in mechanisms/*.yaml; do
    [ -e "$f" ] || { fail "no files in mechanisms"; break; }
    if run "mech check $f" 0 "$MECH" check "$f"; then
        pass
    fi
done

# ---- mech check lists the gears and counts them (docs/format.md 6.4) ----

if run "mech check epicyclic" 0 "$MECH" check mechanisms/epicyclic.yaml; then
    has_line "$tmp/out" "^  gears      g_sp: 'sun' with 'planet', external on 'carrier', r 20:40 mm, z 20:40, ratio -0.5, pressure angle 20 deg\$" "mech check lists a gear pair"
    has_line "$tmp/out" "^  gears      g_pr: 'planet' with 'ground', internal on 'carrier', r 40:100 mm, z 40:100, ratio +0.4, pressure angle 20 deg\$" "mech check lists an internal pair"
    has_line "$tmp/out" '^  mobility   1 = 3\*(4-1) - 2\*3 - 0 - 2 gears, drivers 1$' "mech check counts the gears"
fi

# every option of every command's --help (printed from its option table,
# src/cli/cmd_opts.c) is documented in docs/ (the man page: tests/install.sh)
for c in check equations solve compare batch sweep merge plot animate codegen report fit simulate; do
    "$MECH" "$c" --help | grep -o -- '--[a-z][a-z-]*' | sort -u | while read -r opt; do
        grep -q -- "$opt" docs/*.md || echo "$c $opt"
    done
done >"$tmp/undocumented"
if [ -s "$tmp/undocumented" ]; then fail "options not in docs/*.md: $(tr '\n' ' ' <"$tmp/undocumented")"; else pass; fi

# ---- mech solve ---------------------------------------------------------

# has_line FILE PATTERN LABEL: pass when FILE has a line matching PATTERN

if run "mech solve --help" 0 "$MECH" solve --help; then
    has_line "$tmp/out" '^usage: mech solve' "mech solve --help"
fi

if run "mech solve fourbar" 0 "$MECH" solve mechanisms/fourbar.yaml -o "$tmp/fb.csv" --stats; then
    rows=$(wc -l <"$tmp/fb.csv")
    [ "$rows" -eq 362 ] && pass || fail "mech solve fourbar: $rows lines, expected 362 (header + 361 rows)"
    has_line "$tmp/fb.csv" '^q \[rad\],A\.x \[m\],A\.y \[m\],A\.vx \[m/s\]' "fourbar header"
    has_line "$tmp/err" 'Newton iterations' "mech solve --stats"
    ls "$tmp"/fb.csv.tmp* >/dev/null 2>&1 && fail "a temporary file was left beside the output" || pass
fi

if run "mech solve to stdout" 0 "$MECH" solve mechanisms/slider-crank.yaml --level positions; then
    has_line "$tmp/out" '^q \[rad\],A\.x \[m\],A\.y \[m\],B\.x' "positions-only header"
    grep -q 'vx\|\.omega\|\.a \[' "$tmp/out" && fail "--level positions printed rates" || pass
fi

if run "mech solve --from/--to/--steps" 0 "$MECH" solve mechanisms/fourbar.yaml --from 0 --to 90 --steps 9 -o "$tmp/r.csv"; then
    rows=$(wc -l <"$tmp/r.csv")
    [ "$rows" -eq 11 ] && pass || fail "--steps 9: $rows lines, expected 11"
    last=$(tail -n 1 "$tmp/r.csv" | cut -d, -f1)
    case $last in 1.570796326794896*) pass ;; *) fail "--to 90: last q is $last, expected pi/2 rad" ;; esac
fi

if run "mech solve --outputs --verbose" 0 "$MECH" solve mechanisms/stirling.yaml --outputs D --verbose -o "$tmp/d.csv"; then
    has_line "$tmp/err" 'skipped, no output needs it' "--verbose block report"
    has_line "$tmp/d.csv" '^q \[rad\],D\.x \[m\],D\.y \[m\],D\.vx \[m/s\],D\.vy \[m/s\],D\.ax \[m/s^2\],D\.ay \[m/s^2\]$' "--outputs D header"
fi

if run "mech solve --outputs typo" 2 "$MECH" solve mechanisms/fourbar.yaml --outputs cuopler; then
    has_line "$tmp/err" "did you mean 'coupler'" "--outputs typo"
fi
# a point name on one link only, near a joint's name: a typo that leaves the
# point unconnected is named at its line and column (issue 22 item 6)
cat >"$tmp/typo.yaml" <<'EOF2'
name: Crank-rocker four-bar, a typo
units: {length: mm, angle: deg}
ground: {O: [0, 0], C: [70, 0]}
links:
  crank:   {points: {O: [0, 0], A: [20, 0]}}
  coupler: {points: {A: [0, 0], B: [60, 0], P1: [30, 10]}}
  rocker:  {points: {C: [0, 0], b: [50, 0], P2: [0, 9]}}
driver: {link: crank, angle: {from: 0, to: 360, steps: 36}}
EOF2
if run "mech check, a point name typo" 2 "$MECH" check "$tmp/typo.yaml"; then
    has_line "$tmp/err" "^$tmp/typo.yaml:7:33: warning: point 'b' of link 'rocker' is on no other link and in no joint, so it joins nothing (did you mean 'B', as on link 'coupler'?)$" "point typo: did you mean"
    grep -q "point 'P[12]'" "$tmp/err" && fail "point typo: P1/P2, a numbered series, named" || pass
fi
if run "mech check fourbar: no point typo" 0 "$MECH" check mechanisms/fourbar.yaml; then
    grep -q "joins nothing" "$tmp/err" && fail "fourbar: a point typo warning" || pass
fi

# the other case, and a column's name for its point (issue 22 item 6)
if run "mech solve --outputs b" 2 "$MECH" solve mechanisms/fourbar.yaml --outputs A,b; then
    has_line "$tmp/err" "'b' is not a point.*(did you mean 'B'?)" "--outputs b: the case"
fi
if run "mech solve --outputs B.x" 2 "$MECH" solve mechanisms/fourbar.yaml --outputs B.x; then
    has_line "$tmp/err" "'B.x' is not a point.*(did you mean 'B'?); outputs are names, each giving all its columns" "--outputs B.x: a column"
fi
if run "mech solve --outputs empty item" 2 "$MECH" solve mechanisms/fourbar.yaml --outputs B,,C -o "$tmp/e.csv"; then
    has_line "$tmp/err" "^mech solve: --outputs: item 2 of the list is empty (names are separated by one comma)$" "--outputs B,,C"
    [ ! -e "$tmp/e.csv" ] && pass || fail "--outputs B,,C: wrote $tmp/e.csv"
fi
if run "mech solve --outputs trailing comma" 2 "$MECH" solve mechanisms/fourbar.yaml --outputs B, -o "$tmp/e.csv"; then
    has_line "$tmp/err" "^mech solve: --outputs: item 2 of the list is empty" "--outputs B,"
fi
if run "mech solve --outputs empty" 2 "$MECH" solve mechanisms/fourbar.yaml --outputs "" -o "$tmp/e.csv"; then
    has_line "$tmp/err" "^mech solve: --outputs: the list is empty$" "--outputs ''"
fi
if run "mech solve --outputs twice" 2 "$MECH" solve mechanisms/fourbar.yaml --outputs B,coupler,B -o "$tmp/e.csv"; then
    has_line "$tmp/err" "^mech solve: --outputs: 'B' is listed twice$" "--outputs B,coupler,B"
fi
if run "mech plot --outputs twice" 2 "$MECH" plot mechanisms/fourbar.yaml --outputs coupler,coupler --out "$tmp/figs"; then
    has_line "$tmp/err" "^mech plot: --outputs: 'coupler' is listed twice$" "plot --outputs coupler,coupler"
fi
if run "mech solve --outputs with spaces" 0 "$MECH" solve mechanisms/fourbar.yaml --outputs "A, B" -o "$tmp/ab.csv"; then
    has_line "$tmp/ab.csv" '^q \[rad\],A\.x \[m\],' "--outputs 'A, B'"
fi

run "mech solve bad option" 2 "$MECH" solve mechanisms/fourbar.yaml --frobnicate && pass
run "mech solve --steps 0" 2 "$MECH" solve mechanisms/fourbar.yaml --steps 0 && pass
# options are exact words, parsed by one table-driven parser (src/cli/cmd_opts.c):
# a word that only starts like one, a number that strtod reads but a file
# would refuse (--level positionsXYZ, --steps 0x10 were solved)
if run "mech solve --level positionsXYZ" 2 "$MECH" solve mechanisms/fourbar.yaml --level positionsXYZ -o "$tmp/lv.csv"; then
    has_line "$tmp/err" "^mech solve: --level is positions, velocities or accelerations, not 'positionsXYZ' (did you mean 'positions'?) (see 'mech solve --help')$" "--level positionsXYZ: the message"
    [ ! -e "$tmp/lv.csv" ] && pass || fail "--level positionsXYZ: wrote the CSV"
fi
run "mech solve --level position" 2 "$MECH" solve mechanisms/fourbar.yaml --level position && pass
if run "mech solve --steps 0x10" 2 "$MECH" solve mechanisms/fourbar.yaml --steps 0x10 -o "$tmp/st.csv"; then
    has_line "$tmp/err" "^mech solve: --steps needs a whole number from 1 to 1000000 (as in a file), not '0x10': write it with digits only (see 'mech solve --help')$" "--steps 0x10: the message"
    [ ! -e "$tmp/st.csv" ] && pass || fail "--steps 0x10: wrote the CSV"
fi
for bad in 1e3 16.0 " 16" +16; do
    run "mech solve --steps '$bad'" 2 "$MECH" solve mechanisms/fourbar.yaml --steps "$bad" && pass
done
for args in "sweep mechanisms/slider-crank.yaml --vary r=30mm:40mm:2 -j 0x2" \
            "sweep mechanisms/offset-slider-crank.yaml --random 1e2" \
            "batch -j 2.0 mechanisms/fourbar.yaml" "plot mechanisms/fourbar.yaml --steps 0x10 --out $tmp/figs" \
            "animate mechanisms/fourbar.yaml --frames 1e3" "report mechanisms/fourbar.yaml --steps 1e2" \
            "solve mechanisms/fourbar.yaml --tol 0x1p-30" "compare --rtol inf a.csv b.csv" \
            "codegen mechanisms/fourbar.yaml -o - --friction of" "equations --format LaTeX mechanisms/fourbar.yaml"; do
    # shellcheck disable=SC2086
    if run "mech $args" 2 "$MECH" $args; then
        has_line "$tmp/err" "^mech ${args%% *}: .*, not '.*'.*(see 'mech ${args%% *} --help')$" "mech $args: the message"
    fi
done
# --name=value, a flag with a value, a typo of an option
if run "mech solve --steps=4" 0 "$MECH" solve mechanisms/fourbar.yaml --steps=4 --level=positions; then
    [ "$(wc -l <"$tmp/out")" -eq 6 ] && pass || fail "--steps=4: $(wc -l <"$tmp/out") lines, expected 6"
fi
if run "mech solve --forces=yes" 2 "$MECH" solve mechanisms/fourbar.yaml --forces=yes; then
    has_line "$tmp/err" "^mech solve: option '--forces=yes' takes no value" "--forces=yes"
fi
if run "mech solve --forcse" 2 "$MECH" solve mechanisms/fourbar.yaml --forcse; then
    has_line "$tmp/err" "^mech solve: unknown option '--forcse' (did you mean '--forces'?)" "--forcse"
fi
run "mech solve --from without --to" 2 "$MECH" solve mechanisms/fourbar.yaml --from 10 && pass
run "mech solve --from with a wrong unit" 2 "$MECH" solve mechanisms/fourbar.yaml --from 10kg --to 20 && pass
# command-line ranges are checked like the file's: finite, and positions a
# step can still move (--to 1e20 said "assembles from 0 deg to 0 deg")
if run "mech solve --to 1e20" 2 "$MECH" solve mechanisms/fourbar.yaml --from 0 --to 1e20; then
    has_line "$tmp/err" "within +-1e6 rad" "--to 1e20: the limit named"
fi
run "mech solve --from -1e308" 2 "$MECH" solve mechanisms/fourbar.yaml --from -1e308 --to 0 && pass
run "mech solve --to 1e400" 2 "$MECH" solve mechanisms/fourbar.yaml --from 0 --to 1e400 && pass
run "mech solve --from/--to over 3 turns" 0 "$MECH" solve mechanisms/fourbar.yaml --from -360 --to 720 --steps 3 && pass
# a tolerance below what double precision reaches is refused (1e-300 was
# accepted, then "cannot assemble, residual 7e-18")
if run "mech solve --tol 1e-300" 2 "$MECH" solve mechanisms/fourbar.yaml --tol 1e-300; then
    has_line "$tmp/err" "from 1e-15" "--tol: the limit named"
fi
# forces of a mechanism without masses or loads are all zero: said, not silent
if run "mech solve --forces, no mass" 0 "$MECH" solve mechanisms/slider-crank.yaml --forces; then
    has_line "$tmp/err" "note: no link has a mass and there are no loads" "--forces without masses: a note"
fi
if run "mech solve --forces, masses" 0 "$MECH" solve mechanisms/conveyor.yaml --forces; then
    grep -q "no link has a mass" "$tmp/err" && fail "--forces with masses: the no-mass note" || pass
fi
if run "mech sweep --forces, no mass" 0 "$MECH" sweep mechanisms/slider-crank.yaml --vary r=30mm:60mm:3 --forces; then
    [ "$(grep -c 'no link has a mass' "$tmp/err")" -eq 1 ] && pass || fail "sweep --forces without masses: expected the note once: $(cat "$tmp/err")"
fi
run "mech solve --tol nan" 2 "$MECH" solve mechanisms/fourbar.yaml --tol nan && pass
run "mech solve --tol 1e-15" 0 "$MECH" solve mechanisms/fourbar.yaml --tol 1e-15 && pass
# out of memory has its own message and exit status 3, not 2 "invalid input"
# (a memory limit does not work with AddressSanitizer's shadow memory)
if ! grep -q __asan_init "$MECH"; then
    if run "mech solve out of memory" 3 sh -c "ulimit -v 200000; exec \"\$0\" solve mechanisms/conveyor.yaml --steps 1000000 --forces" "$MECH"; then
        has_line "$tmp/err" "out of memory" "out of memory: said"
    fi
fi
run "mech solve missing file" 3 "$MECH" solve "$tmp/nonexistent.yaml" && pass
run "mech solve unwritable output" 3 "$MECH" solve mechanisms/fourbar.yaml -o "$tmp/no/such/dir/x.csv" && pass

# crank 40, coupler 50, rocker 45, ground 60 mm: the loop closes while
# |CA| <= 50 + 45, i.e. cos q >= (40^2 + 60^2 - 95^2) / (2 40 60): |q| <= 142.833 deg
# Partial sweeps (issue 17): the rows that exist are written, each gap is
# listed with its limits, exit 1; --within-assembly makes that the request.
if run "mech solve non-Grashof" 1 "$MECH" solve tests/solve/non-grashof.yaml -o "$tmp/old.csv"; then
    has_line "$tmp/err" 'cannot assemble at driver angle = 143 deg.*assembles for driver angle from -142.83[0-9]* deg to 142.83[0-9]* deg' "non-Grashof message"
    has_line "$tmp/err" '^mech solve: gap: rows 144 to 218 of 361 (driver at 143.000000 deg to 217.000000 deg) not solved: the mechanism does not assemble; limits found: from 142.8327145[0-9] deg to 217.1672854[0-9] deg$' "non-Grashof gap"
    has_line "$tmp/err" '^mech solve: 286 rows solved (361 positions requested); the rows solved are written$' "non-Grashof rows count"
    has_line "$tmp/err" '(limit positions; at 142.8327145 deg, coupler and rocker extended in line)$' "non-Grashof: the links in line at the limit"
    [ "$(wc -l <"$tmp/old.csv")" -eq 287 ] && pass || fail "non-Grashof: $(wc -l <"$tmp/old.csv") lines written, expected 287 (header and 286 rows)"
fi
run "mech solve non-Grashof --within-assembly" 0 "$MECH" solve tests/solve/non-grashof.yaml --within-assembly -o "$tmp/wa.csv" && pass
if run "mech solve non-Grashof --range assembly" 0 "$MECH" solve tests/solve/non-grashof.yaml --range assembly -o "$tmp/ra.csv"; then
    [ "$(wc -l <"$tmp/ra.csv")" -eq 289 ] && pass || fail "--range assembly: $(wc -l <"$tmp/ra.csv") lines, expected 289 (286 rows and the two limits)"
    has_line "$tmp/ra.csv" '^2.492901' "--range assembly: a row at the limit 142.8327 deg (2.492901 rad)"
fi
if run "mech sweep with a partial variant" 0 "$MECH" sweep mechanisms/double-crank.yaml --vary 'l0=20mm:80mm:2' -o "$tmp/sw.csv"; then
    has_line "$tmp/err" '^360 of 361 rows solved, 1 gap$' "sweep: rows and gaps of a partial variant"
    has_line "$tmp/sw.csv" '^1,0.08,no-assembly,360$' "sweep: the partial variant's rows"
fi
run "mech solve --range bogus" 2 "$MECH" solve tests/solve/non-grashof.yaml --range bogus && pass
if run "mech solve change point --within-assembly" 1 "$MECH" solve tests/hard/change-point.yaml --within-assembly -o "$tmp/cp.csv"; then
    has_line "$tmp/err" '^mech solve: gap: row 181 of 361 (driver at 180.000000 deg) not solved: a change point, where two assembly branches cross' "change-point gap"
fi

if run "mech solve dead centre" 1 "$MECH" solve tests/solve/dead-centre.yaml -o "$tmp/dc.csv"; then
    has_line "$tmp/err" 'singular position at driver displacement = 180 mm.*dead point.*th_crank (at 0.000 deg), th_rod (at 0.000 deg)' "dead-centre message"
    has_line "$tmp/err" 'a dead point, toggle or limit position (crank and rod extended in line: dead centre of the slider)' "dead centre named"
    has_line "$tmp/err" '^mech solve: gap: row 31 of 31 (driver at 180.000000 mm) not solved: a dead point or limit position the driver cannot pass; limits found: from 180.0000000[0-9]* mm$' "dead-centre gap"
    [ "$(wc -l <"$tmp/dc.csv")" -eq 31 ] && pass || fail "dead centre: $(wc -l <"$tmp/dc.csv") lines written, expected 31"
fi
run "mech solve dead centre --within-assembly" 0 "$MECH" solve tests/solve/dead-centre.yaml --within-assembly -o "$tmp/dc2.csv" && pass

# issue 32 point 10: a crank far too long (tests/solve/crank-too-long.yaml) is
# "cannot assemble" at the first driver value, naming the loop and the links
# that cannot reach, not a "singular position" (reciprocal condition 0.41,
# far above the limit); as a sweep variant its status is no-assembly
if run "mech solve, a crank far too long" 1 "$MECH" solve tests/solve/crank-too-long.yaml -o "$tmp/long.csv"; then
    has_line "$tmp/err" 'error: cannot assemble at driver angle = 0 deg: loop 1 (B-C-O-A-B) does not close (residual 0.02 m at best, .* where coupler and rocker are at the limit of their reach)' "crank too long: cannot assemble, the loop and the links"
    grep -q singular "$tmp/err" && fail "crank too long: called singular: $(head -n 1 "$tmp/err")" || pass
    has_line "$tmp/err" '^mech solve: gap: rows 1 to 37 of 37 .* not solved: the mechanism does not assemble$' "crank too long: the gap's kind"
fi
if run "mech sweep, a crank far too long" 0 "$MECH" sweep tests/solve/crank-too-long.yaml --list r=20mm,200mm -o "$tmp/long-sweep.csv"; then
    has_line "$tmp/long-sweep.csv" '^0,0.02,ok,37$' "sweep: the crank-rocker solves"
    has_line "$tmp/long-sweep.csv" '^1,0.2,no-assembly,0$' "sweep: a crank far too long is no-assembly (not singular)"
fi
sed 's|^ground:|parameters: {r: 40 mm}\nground:|; s|A: \[40, 0\]|A: [r, 0]|' tests/solve/dead-centre.yaml >"$tmp/dc-r.yaml"
if run "mech sweep, a dead centre" 0 "$MECH" sweep "$tmp/dc-r.yaml" --list r=40mm,30mm --unsolvable-ok -o "$tmp/dc-sweep.csv"; then
    has_line "$tmp/dc-sweep.csv" '^0,0.04,singular,30$' "sweep: a dead point's status is singular (from its kind)"
    has_line "$tmp/dc-sweep.csv" '^1,0.03,singular,20$' "sweep: the shorter crank's dead centre at 170 mm, a row"
fi

if run "mech solve --forces --friction both" 0 "$MECH" solve mechanisms/conveyor.yaml --friction both --stats -o "$tmp/cv.csv"; then
    has_line "$tmp/cv.csv" '^q \[rad\],.*,O\.Fx \[N\],O\.Fy \[N\],O\.F \[N\],.*driver\.torque \[N\*m\],power\.residual \[-\],friction\.power \[W\],friction\.iterations \[-\],.*driver\.torque\.nofriction \[N\*m\],power\.residual\.nofriction \[-\]$' "--friction both header"
    has_line "$tmp/err" 'power balance      worst relative residual' "--stats power balance"
fi
if run "mech solve --forces on a file without forces" 0 "$MECH" solve mechanisms/fourbar.yaml --forces --level positions -o "$tmp/fb4.csv"; then
    has_line "$tmp/fb4.csv" 'A\.ax \[m/s^2\].*driver\.torque \[N\*m\]' "--forces implies accelerations"
fi
run "mech solve --friction bogus" 2 "$MECH" solve mechanisms/conveyor.yaml --friction bogus && pass

# springs and dampers (docs/forces.md section 7), flywheel figures (section 8)
ssc=mechanisms/spring-slider-crank.yaml
if run "mech check springs" 0 "$MECH" check $ssc; then
    [ "$(grep -c '^  spring     ' "$tmp/out")" -eq 3 ] && pass || fail "check: 3 spring lines"
    has_line "$tmp/out" '^  spring     return: linear S-B (ground, piston), stiffness 2000 N/m, free length 0.25 m, preload -5 N$' "check: a spring listed"
    has_line "$tmp/out" '^  spring     pivot: torsional at O (crank, ground), stiffness 0.5 N\*m/rad, free angle 0 deg$' "check: a torsional spring listed"
fi
# loads that depend on the motion (docs/format.md 10.2)
if run "mech check state loads" 0 "$MECH" check mechanisms/stirling-gas.yaml; then
    [ "$(grep -c '^  load       ' "$tmp/out")" -eq 2 ] && pass || fail "check: 2 load lines"
    has_line "$tmp/out" "^  load       force at D on link 'piston3', depends on the motion\$" "check: a state load listed"
fi
if run "mech solve springs --stats" 0 "$MECH" solve $ssc --stats -o "$tmp/ss.csv"; then
    has_line "$tmp/ss.csv" 'return\.length \[m\],return\.rate \[m/s\],return\.force \[N\],damper\.length \[m\],damper\.rate \[m/s\],damper\.force \[N\],pivot\.angle \[rad\],pivot\.rate \[rad/s\],pivot\.torque \[N\*m\]$' "spring columns"
    has_line "$tmp/err" 'flywheel           mean driver torque .* N\*m over 360 deg (one turn)' "--stats flywheel"
    has_line "$tmp/err" 'energy fluctuation .* J (energy lowest at q = ' "--stats energy fluctuation"
    has_line "$tmp/err" '(--speed-fluctuation CS gives the flywheel inertia)' "--stats flywheel hint"
fi
if run "mech solve --speed-fluctuation" 0 "$MECH" solve $ssc --speed-fluctuation 0.02 -o "$tmp/ss2.csv"; then
    has_line "$tmp/err" 'inertia .* kg\*m^2 for a speed fluctuation of 0.02 at 62.8319 rad/s' "--speed-fluctuation inertia"
fi
if run "mech solve --stats half a turn" 0 "$MECH" solve $ssc --stats --from 0 --to 180 -o "$tmp/ss3.csv"; then
    has_line "$tmp/err" 'over 180 deg: NOT one full turn' "--stats flywheel: not a cycle"
fi
if run "mech solve --speed-fluctuation implies forces" 0 "$MECH" solve mechanisms/slider-crank.yaml --speed-fluctuation 0.05 -o "$tmp/ss4.csv"; then
    has_line "$tmp/ss4.csv" 'driver\.torque' "--speed-fluctuation: torque column"
fi
run "mech solve --speed-fluctuation 0" 2 "$MECH" solve $ssc --speed-fluctuation 0 && pass
run "mech solve --speed-fluctuation 1" 2 "$MECH" solve $ssc --speed-fluctuation 1 && pass
run "mech solve --speed-fluctuation x" 2 "$MECH" solve $ssc --speed-fluctuation x && pass
if run "mech sweep flywheel metric" 0 "$MECH" sweep $ssc --vary r=30mm:40mm:2 --forces --metric flywheel:0.02 -q; then
    has_line "$tmp/out" 'flywheel:0.02 \[kg\*m^2\]' "sweep: flywheel metric header"
fi
run "mech sweep flywheel:2" 2 "$MECH" sweep $ssc --vary r=30mm:40mm:2 --forces --metric flywheel:2 && pass
run "mech sweep flywheel without --forces" 2 "$MECH" sweep mechanisms/slider-crank.yaml --vary r=30mm:40mm:2 --metric flywheel:0.02 && pass

for f in mechanisms/*.yaml; do
    run "mech solve $f" 0 "$MECH" solve "$f" -o "$tmp/all.csv" && pass
done

# --linear-solver: KLU and the dense blocks give the same table (to 1e-12 of
# each column's values), --verbose says which ran, a bad value is a usage error
if run "mech solve --linear-solver klu" 0 "$MECH" solve mechanisms/stirling.yaml \
       --linear-solver klu --verbose -o "$tmp/klu.csv" &&
   grep -q '^linear solves: KLU$' "$tmp/err" &&
   run "mech solve --linear-solver auto" 0 "$MECH" solve mechanisms/stirling.yaml \
       --verbose -o "$tmp/auto.csv" &&
   grep -q '^linear solves: dense blocks (6 blocks, largest 2x2)$' "$tmp/err" &&
   run "compare klu with auto" 0 "$MECH" compare "$tmp/auto.csv" "$tmp/klu.csv" \
       --rtol 1e-12 --atol 1e-13; then
    pass
else
    fail "mech solve --linear-solver: KLU and dense blocks differ, or --verbose does not say"
fi
if run "mech solve --linear-solver bad" 2 "$MECH" solve mechanisms/stirling.yaml \
       --linear-solver lapack; then
    has_line "$tmp/err" "needs auto or klu, not 'lapack'" "--linear-solver lapack"
fi

# ---- mech batch -----------------------------------------------------------

if run "mech batch --help" 0 "$MECH" batch --help; then
    has_line "$tmp/out" '^usage: mech batch' "mech batch --help"
fi
mkdir "$tmp/bo"
if run "mech batch all goldens" 0 "$MECH" batch -j 2 -q --out-dir "$tmp/bo" --golden tests/golden mechanisms/*.yaml; then
    n=$(grep -c ' ok .* match$' "$tmp/out")
    m=$(ls mechanisms/*.yaml | wc -l)
    [ "$n" -eq "$m" ] && pass || fail "mech batch: $n of $m files ok and matching"
    # the same doubles (the golden's %.17g text and the shortest text read back equal)
    "$MECH" compare "$tmp/bo/fourbar.csv" tests/golden/fourbar.csv --rtol 0 --atol 0 >/dev/null &&
        pass || fail "mech batch: fourbar.csv differs from a single solve's golden"
fi
if run "mech batch with failures" 1 "$MECH" batch -j 3 mechanisms/fourbar.yaml tests/solve/non-grashof.yaml tests/bad/01-bad-indentation.yaml mechanisms/slider-crank.yaml; then
    has_line "$tmp/out" '^non-grashof  *FAILED' "batch: failing file reported"
    has_line "$tmp/err" 'tests/solve/non-grashof.yaml: 286 of 361 rows solved, 1 gap$' "batch: rows and gaps of a partial sweep"
    has_line "$tmp/out" '^slider-crank  *ok' "batch: files after a failure still solved"
    has_line "$tmp/err" 'cannot assemble at driver angle = 143 deg' "batch: messages kept per file"
fi
if run "mech batch --shard" 0 "$MECH" batch -q --shard 1/2 mechanisms/fourbar.yaml mechanisms/slider-crank.yaml mechanisms/stirling.yaml; then
    lines=$(grep -c ' ok ' "$tmp/out")
    [ "$lines" -eq 1 ] && grep -q '^slider-crank ' "$tmp/out" && pass || fail "--shard 1/2 of 3 files: expected only slider-crank, got $(cat "$tmp/out")"
fi
run "mech batch --shard 2/2" 2 "$MECH" batch --shard 2/2 mechanisms/fourbar.yaml && pass
run "mech batch no files" 2 "$MECH" batch -j 2 && pass

# ---- mech plot ------------------------------------------------------------

# a long sweep is thinned to what a figure shows (200 000 steps wrote 71 MB)
if run "mech plot --steps 200000" 0 "$MECH" plot mechanisms/fourbar.yaml --steps 200000 --out "$tmp/fig"; then
    kb=$(du -sk "$tmp/fig" | cut -f1)
    [ "$kb" -lt 3000 ] && pass || fail "plot of 200 000 steps: $kb KB of SVG, expected under 3 MB"
fi

# --set, --from, --to: the semantics and messages of mech solve
if run "mech plot --set --from --to" 0 "$MECH" plot mechanisms/slider-crank.yaml --set 'r=50 mm' --from 0 --to 180 --steps 4 --outputs B --out "$tmp/pst"; then
    has_line "$tmp/out" "/slider-crank-path-B.svg\$" "plot: a path figure for the moving point B"
    # the path of B, through data-mech-transform, ends at l - r = 90 mm (r = 50 mm, 180 deg)
    tr=$(sed -n 's/.*data-mech-transform="\([^"]*\)".*/\1/p' "$tmp/pst/slider-crank-path-B.svg")
    last=$(sed -n 's/.*<path stroke="#1f4e99" d="\([^"]*\)".*/\1/p' "$tmp/pst/slider-crank-path-B.svg" | awk '{print $NF}')
    echo "$tr $last" | awk '{ split($4, v, ","); x = (v[1] - $2) / $1; exit !(x > 0.08999 && x < 0.09001) }' && pass ||
        fail "plot --set r=50mm --to 180: path of B ends at $last (transform $tr), not at x = 90 mm"
    "$MECH" solve mechanisms/slider-crank.yaml --set 'r=50 mm' --from 0 --to 180 --steps 4 --outputs B --level positions -o "$tmp/pst.csv" &&
        has_line "$tmp/pst.csv" '^3.14159[0-9]*,0.09[0-9]*,' "solve --set r=50mm --to 180: B.x = l - r = 90 mm"
fi
for cmd in plot animate; do
    if run "mech $cmd --from without --to" 2 "$MECH" $cmd mechanisms/fourbar.yaml --from 10; then
        has_line "$tmp/err" "^mech $cmd: --from and --to go together (see 'mech $cmd --help')$" "$cmd --from alone"
    fi
    if run "mech $cmd --set without =" 2 "$MECH" $cmd mechanisms/fourbar.yaml --set r; then
        has_line "$tmp/err" "^mech $cmd: --set needs NAME=VALUE (at most 64), not 'r' (see 'mech $cmd --help')$" "$cmd --set r"
    fi
    if run "mech $cmd --set unknown parameter" 2 "$MECH" $cmd mechanisms/slider-crank.yaml --set rr=4mm; then
        has_line "$tmp/err" "no parameter 'rr'" "$cmd --set rr="
    fi
    if run "mech $cmd --from not a number" 2 "$MECH" $cmd mechanisms/fourbar.yaml --from ten --to 20; then
        has_line "$tmp/err" "^mech $cmd: --from 'ten': " "$cmd --from ten"
    fi
    if run "mech $cmd --to too far" 2 "$MECH" $cmd mechanisms/fourbar.yaml --from 0 --to 1e9; then
        has_line "$tmp/err" "^mech $cmd: --to '1e9' is 1.75e+07 rad: a driver angle must be within" "$cmd --to 1e9"
    fi
done
# the same words as mech solve
"$MECH" solve mechanisms/fourbar.yaml --from ten --to 20 2>"$tmp/e1" >/dev/null
"$MECH" plot mechanisms/fourbar.yaml --from ten --to 20 --out "$tmp/f2" 2>"$tmp/e2" >/dev/null
[ "$(sed 's/^mech solve/mech X/' "$tmp/e1")" = "$(sed 's/^mech plot/mech X/' "$tmp/e2")" ] && pass ||
    fail "plot --from ten: '$(cat "$tmp/e2")' is not solve's '$(cat "$tmp/e1")'"
# animate --outputs: the traced points
if run "mech animate --outputs" 0 "$MECH" animate mechanisms/fourbar.yaml --outputs P --frame 3 -o "$tmp/tr.svg"; then
    [ "$(grep -c 'data-trace=' "$tmp/tr.svg")" -eq 1 ] && grep -q 'data-trace="P"' "$tmp/tr.svg" && pass ||
        fail "animate --outputs P: traces $(grep -o 'data-trace="[^"]*"' "$tmp/tr.svg" | paste -sd' ' -)"
    grep -q 'data-mech-scale-bar=' "$tmp/tr.svg" && pass || fail "animate: no scale bar"
fi
if run "mech animate --outputs link" 2 "$MECH" animate mechanisms/fourbar.yaml --outputs P,coupler -o "$tmp/tr2.svg"; then
    has_line "$tmp/err" "^mech animate: --outputs: 'coupler' is a link, not a point: the animation traces the paths of points$" "animate --outputs coupler"
    [ ! -e "$tmp/tr2.svg" ] && pass || fail "animate --outputs coupler wrote $tmp/tr2.svg"
fi
if run "mech animate --outputs unknown" 2 "$MECH" animate mechanisms/fourbar.yaml --outputs Q -o "$tmp/tr2.svg"; then
    has_line "$tmp/err" "^mech animate: --outputs: 'Q' is not a point" "animate --outputs Q"
fi
# 10^6 steps: every figure of bounded size (the paths and the curves thinned)
if [ -z "$MECH_QUICK" ] && run "mech plot --steps 1000000" 0 "$MECH" plot mechanisms/fourbar.yaml --steps 1000000 --outputs P,coupler --out "$tmp/fig6"; then
    big=$(find "$tmp/fig6" -name '*.svg' -size +200k | head -n 1)
    [ -z "$big" ] && pass || fail "plot of 10^6 steps: $big is over 200 kB"
    [ -s "$tmp/fig6/fourbar-path-P.svg" ] && pass || fail "plot of 10^6 steps: no path figure"
fi

# ---- mech sweep -----------------------------------------------------------

if run "mech sweep" 0 "$MECH" sweep mechanisms/slider-crank.yaml --vary r=30mm:60mm:4 --list l=45mm,140mm --metric range:x_B.s -j 2 -o "$tmp/sw.csv"; then
    has_line "$tmp/sw.csv" '^variant \[-\],r \[m\],l \[m\],status \[-\],rows \[-\],range:x_B.s \[m\]$' "sweep header: name [unit], as the solve CSV"
    has_line "$tmp/sw.csv" '^7,0.06,0.14,ok,73,0.12$' "sweep: stroke = 2 r"
    has_line "$tmp/sw.csv" '^6,0.06,0.045,no-assembly,' "sweep: a variant that cannot assemble is a row, not a failure"
fi
if run "mech sweep --shard" 0 "$MECH" sweep mechanisms/slider-crank.yaml --vary r=30mm:60mm:4 --list l=45mm,140mm --metric range:x_B.s --shard 1/3; then
    rows=$(grep -c '^[0-9]' "$tmp/out")
    [ "$rows" -eq 3 ] && grep -q '^4,' "$tmp/out" && pass || fail "sweep --shard 1/3 of 8: expected variants 1, 4, 7"
fi
if run "mech sweep unknown parameter" 2 "$MECH" sweep mechanisms/slider-crank.yaml --list rr=40mm; then
    has_line "$tmp/err" "no parameter 'rr'" "sweep: unknown parameter named"
fi
run "mech sweep bad range" 2 "$MECH" sweep mechanisms/slider-crank.yaml --vary r=30mm:60:4 && pass
# a metric's column is checked before anything is solved (it gave nan rows, exit 0)
sc=mechanisms/slider-crank.yaml
if run "mech sweep unknown metric column" 2 "$MECH" sweep $sc --vary r=30mm:60mm:4 --metric range:x_B.ss; then
    has_line "$tmp/err" "no column 'x_B.ss' in the output.*did you mean 'x_B.s'" "sweep: unknown metric column named"
    [ -s "$tmp/out" ] && fail "sweep: unknown metric column: rows written" || pass
fi
run "mech sweep range:nosuch" 2 "$MECH" sweep $sc --vary r=30mm:60mm:2 --metric range:nosuch && pass
run "mech sweep torque metric without --forces" 2 "$MECH" sweep $sc --vary r=30mm:60mm:2 --metric maxabs:driver.torque && pass
if run "mech sweep transmission: unknown link" 2 "$MECH" sweep $sc --vary r=30mm:60mm:2 --metric transmission:crank,rid; then
    has_line "$tmp/err" "no column 'rid.angle'.*did you mean 'rod.angle'" "sweep: transmission link named"
fi
# the first variant cannot assemble: its columns are known all the same
if run "mech sweep, first variant fails" 0 "$MECH" sweep $sc --vary r=60mm:30mm:4 --list l=45mm,140mm --metric range:x_B.s; then
    has_line "$tmp/out" '^0,0.06,0.045,no-assembly,' "sweep: variant 0 cannot assemble"
    has_line "$tmp/out" '^1,0.06,0.14,ok,73,0.12$' "sweep: the others are solved"
fi
# every variant fails: exit 1, the rows still written
if run "mech sweep, no variant solved" 1 "$MECH" sweep $sc --vary r=300mm:600mm:2 --metric range:x_B.s; then
    rows=$(grep -c ',no-assembly,' "$tmp/out")
    [ "$rows" -eq 2 ] && pass || fail "sweep, no variant solved: $rows no-assembly rows, expected 2"
    has_line "$tmp/err" "none of the 2 variants could be solved" "sweep: no variant solved, said"
fi
run "mech sweep, a parameter varied twice" 2 "$MECH" sweep $sc --vary r=30mm:60mm:2 --list r=45mm && pass
# a --list value cannot add rows or cells to the CSV
nl='
'
if run "mech sweep --list with a newline" 2 "$MECH" sweep $sc --list "l=140mm${nl}99,injected"; then
    has_line "$tmp/err" "control character (byte 0x0a)" "sweep: control character named"
    [ -s "$tmp/out" ] && fail "sweep --list with a newline: rows written" || pass
fi
if run "mech sweep --list with a quote" 2 "$MECH" sweep $sc --list 'l=140mm,"9"'; then
    has_line "$tmp/err" "value '\"9\"' is not a number with a unit" "sweep: a value that is not a quantity is refused"
    [ -s "$tmp/out" ] && fail "sweep --list with a quote: rows written" || pass
fi

# the sweep CSV is the solve CSV's dialect (issue 22 item 5): SI numbers,
# 'name [unit]' headers, bare parameters in '-', no trailing spaces
if run "mech sweep, the CSV dialect" 0 "$MECH" sweep mechanisms/jansen.yaml --vary La=37:39:3 \
        --list 'Lb=41.5' --metric transmission:upper,foot --metric maxabs:foot.omega -j 2; then
    has_line "$tmp/out" '^variant \[-\],La \[-\],Lb \[-\],status \[-\],rows \[-\],transmission:upper/foot \[rad\],maxabs:foot.omega \[rad/s\]$' "sweep: bare parameters in '-', transmission in rad"
    has_line "$tmp/out" '^1,38,41.5,ok,' "sweep: a bare value written as its number"
    grep -q ' $' "$tmp/out" && fail "sweep: a trailing space in the CSV" || pass
fi
if run "mech sweep, a value in another dimension" 2 "$MECH" sweep $sc --list l=140mm,2kg; then
    has_line "$tmp/err" "value '2kg' is in kg, '140mm' in m" "sweep: mixed dimensions refused"
fi
if run "mech sweep, a value in the wrong dimension" 2 "$MECH" sweep $sc --list l=2kg; then
    has_line "$tmp/err" "parameter 'l' replaced by '2kg': a quantity in kg, where the file's '140 mm' is in m" "sweep: the parameter's dimension"
fi

# ---- bare driver angles are radians (issue 16 item 8) -----------------------

cat >"$tmp/rad.yaml" <<'EOF2'
name: four-bar in radians by mistake
units: {length: mm}
ground: {O: [0, 0], C: [70, 0]}
links:
  crank:   {points: {O: [0, 0], A: [20, 0]}}
  coupler: {points: {A: [0, 0], B: [60, 0]}}
  rocker:  {points: {C: [0, 0], B: [50, 0]}}
driver: {link: crank, angle: {from: 0, to: 360, steps: 360}}
EOF2
rad_warning="rad.yaml:8:30: warning: driver angle numbers without a unit are radians: this range spans 57.3 revolutions in steps of up to 57.3 deg; for degrees write 'units: {angle: deg}' or '360 deg'"
if run "mech check bare radians" 0 "$MECH" check "$tmp/rad.yaml"; then
    has_line "$tmp/err" "$rad_warning" "check: bare driver angles warn"
fi
if run "mech solve bare radians" 0 "$MECH" solve "$tmp/rad.yaml" -o "$tmp/rad.csv"; then
    has_line "$tmp/err" "$rad_warning" "solve: bare driver angles warn"
fi
for f in mechanisms/*.yaml; do
    if run "mech check $f" 0 "$MECH" check "$f"; then
        if grep -q 'warning' "$tmp/err"; then fail "$f: warns: $(head -n 1 "$tmp/err")"; else pass; fi
    fi
done

# issue 16 item 7: a result that is not a finite number is an error (it wrote
# 4332 nan/inf cells and exited 0): exit 1, the column and the position named,
# no file written
sed 's|speed: 10 rad/s|speed: 1e160 rad/s|' mechanisms/fourbar.yaml > "$tmp/fast.yaml"
if run "mech solve, speed 1e160 rad/s" 1 "$MECH" solve "$tmp/fast.yaml" -o "$tmp/fast.csv"; then
    has_line "$tmp/err" "at driver angle = 0 deg the column A.ax is NaN, not a finite number" \
        "solve: non-finite result named"
    [ -e "$tmp/fast.csv" ] && fail "solve: non-finite result: a file was written" || pass
fi

# issue 22 item 4: progress of long runs on standard error, a line every
# MECH_PROGRESS_SECONDS when it is not a terminal (0: every report); -q none
if run "mech solve, progress" 0 env MECH_PROGRESS_SECONDS=0 "$MECH" solve mechanisms/fourbar.yaml --steps 10000 -o "$tmp/prog.csv"; then
    has_line "$tmp/err" '^mech solve: 4096 of 10001 rows (40%), [0-9]* s$' "solve: progress lines"
fi
if run "mech solve -q, no progress" 0 env MECH_PROGRESS_SECONDS=0 "$MECH" solve mechanisms/fourbar.yaml --steps 10000 -q -o "$tmp/prog.csv"; then
    grep -q 'rows (' "$tmp/err" && fail "solve -q: progress printed" || pass
fi
if run "mech sweep, progress" 0 env MECH_PROGRESS_SECONDS=0 "$MECH" sweep mechanisms/slider-crank.yaml --vary r=30mm:40mm:3 -j 1 -o "$tmp/prog-sweep.csv"; then
    has_line "$tmp/err" '^mech sweep: 2 of 3 variants (66%), [0-9]* s$' "sweep: progress lines"
fi
if run "mech batch, progress" 0 env MECH_PROGRESS_SECONDS=0 "$MECH" batch -j 1 mechanisms/fourbar.yaml mechanisms/slider-crank.yaml; then
    has_line "$tmp/err" '^mech batch: 1 of 2 files (50%), [0-9]* s$' "batch: progress lines"
fi

# issue 20: parameters kept symbolic (mech equations) and sensitivities
if run "mech equations, parameter names" 0 "$MECH" equations mechanisms/offset-slider-crank.yaml; then
    has_line "$tmp/out" "^  f1 = l\*cos(th_rod) - x_B + r\*cos(th_crank) " "equations: r and l by name"
    has_line "$tmp/out" "^  f2 = l\*sin(th_rod) - e + r\*sin(th_crank) " "equations: e by name"
fi
if run "mech solve --sensitivity" 0 "$MECH" solve mechanisms/offset-slider-crank.yaml --steps 4 -q --sensitivity r,l; then
    has_line "$tmp/out" '^q \[rad\],.*,d(A\.x)/d(r) \[m/m\],.*,d(x_B\.a)/d(l) \[m/s^2/m\]$' "sensitivity: header"
    # A = r (cos q, sin q): d(A.x)/d(r) = cos q, 1 at q = 0; d(A.vy)/d(r) = w cos q = 314.159...
    ax=$(awk -F, 'NR == 2 { print $20 }' "$tmp/out")
    [ "$ax" = "1" ] && pass || fail "sensitivity: d(A.x)/d(r) at q = 0 is '$ax', not 1"
fi
if run "mech solve --sensitivity, unknown name" 2 "$MECH" solve mechanisms/offset-slider-crank.yaml --steps 4 -q --sensitivity rr; then
    has_line "$tmp/err" "no parameter 'rr' in the file (its parameters: r, l, e)" "sensitivity: unknown name"
fi

# issue 20 item 4: tolerances
sed 's/^  r: 40 mm .*/  r: {value: 40 mm, tolerance: 0.05 mm}/; s/^  l: 120 mm .*/  l: {value: 120 mm, tolerance: 0.1 mm}/' \
    mechanisms/offset-slider-crank.yaml >"$tmp/tol.yaml"
if run "mech solve --tolerances" 0 "$MECH" solve "$tmp/tol.yaml" -q --tolerances --outputs B -o "$tmp/tol.csv"; then
    has_line "$tmp/err" '^mech solve: tolerance stack-up, first order, from r +-5e-05 m l +-0.0001 m; largest over the 361 rows:$' "tolerances: summary head"
    # by hand at q = 240 deg: |dx/dr| tol_r + |dx/dl| tol_l = 1.05371 * 5e-5 + 1.18692 * 1e-4 (docs/sensitivity.md)
    has_line "$tmp/err" '^  B.x  *worst case 0.000171378  *RSS 0.000130621  *\[m\] (worst at q = 4.18879)$' "tolerances: B.x stack-up"
    has_line "$tmp/tol.csv" '^q \[rad\],B.x \[m\],.*,worst(B.x) \[m\],rss(B.x) \[m\],' "tolerances: columns"
fi
sed 's/tolerance: 0.05 mm/tolerance: 0.05/' "$tmp/tol.yaml" >"$tmp/tol-bad.yaml"
if run "tolerance without a unit" 2 "$MECH" check "$tmp/tol-bad.yaml"; then
    has_line "$tmp/err" "tol-bad.yaml:53:32: error: tolerance of parameter 'r' must be in the value's unit (m), not '0.05'" "tolerance: unit"
    [ "$(wc -l <"$tmp/err")" -eq 1 ] && pass || fail "tolerance without a unit: echoed errors: $(cat "$tmp/err")"
fi
if run "mech solve --tolerances without tolerances" 2 "$MECH" solve mechanisms/offset-slider-crank.yaml -q --tolerances; then
    has_line "$tmp/err" "no parameter has a tolerance" "tolerances: none"
fi
for bad in "r,,l" "r," "r,r" ""; do
    if run "mech solve --sensitivity '$bad'" 2 "$MECH" solve mechanisms/offset-slider-crank.yaml -q --sensitivity "$bad"; then
        has_line "$tmp/err" "sensitivity needs at most 64 different parameter names separated by commas" "sensitivity: '$bad'"
    fi
done
sed 's/^  e: 30 mm .*/  e: 30 mm\n  alpha: 0 deg/; s/^    angle: 0 deg .*/    angle: alpha/' \
    mechanisms/offset-slider-crank.yaml >"$tmp/angle.yaml"
if run "mech solve --sensitivity, a slider's angle" 2 "$MECH" solve "$tmp/angle.yaml" -q --steps 4 --sensitivity alpha; then
    has_line "$tmp/err" "error: parameter 'alpha' sets the angle of slider 'x_B': sensitivities through a slider's angle are not computed" "sensitivity: slider angle refused"
fi
run "mech solve --sensitivity r, a slider's angle elsewhere" 0 "$MECH" solve "$tmp/angle.yaml" -q --steps 4 --sensitivity r && pass

# ---- messages found on the way (issue 28 point 5) --------------------------
cat >"$tmp/p5.yaml" <<'EOF2'
name: four-bar with a coupler point from parameters
units: {length: mm, angle: deg}
parameters:
  c: 30 mm
  a: 20 mm
  b: 25 mm
ground: {O: [0, 0], C: [70, 0]}
links:
  crank:   {points: {O: [0, 0], A: [20, 0]}}
  coupler: {points: {A: [0, 0], B: [60, 0], P: [c * c / a, 10]}}
  rocker:  {points: {C: [0, 0], B: [50, 0]}}
driver: {link: crank, angle: {from: 0, to: 360, steps: 4}}
initial: {coupler: 44.6, rocker: 146}
outputs: {points: [A, B, P]}
EOF2
# a bare --vary value for a parameter with a unit: the option and the value named
if run "sweep: bare --vary values" 2 "$MECH" sweep "$tmp/p5.yaml" --vary c=0:1000:3; then
    has_line "$tmp/err" "^mech sweep: --vary c=0:1000:3: the value '0' has no unit, but parameter 'c' has one in the file (c = 0.03 m, line 4)" "sweep: bare value named"
fi
run "sweep: --vary with units" 0 "$MECH" sweep "$tmp/p5.yaml" --vary c=20mm:40mm:3 && pass
# an unquoted min(a, b) in [x, y]: the hint to quote it
sed 's/P: \[c \* c \/ a, 10\]/P: [min(a, b), 10]/' "$tmp/p5.yaml" >"$tmp/p5-min.yaml"
if run "check: min(a, b) unquoted" 2 "$MECH" check -q "$tmp/p5-min.yaml"; then
    has_line "$tmp/err" "p5-min.yaml:10:48: error: point 'P' of link 'coupler' must be a list of two values \[x, y\], not of 3: the commas of an expression split it; quote it: 'min(a, b)'$" "min(a, b): quote it"
fi
sed "s/P: \[c \* c \/ a, 10\]/P: ['c * atan2(a, b) \/ atan2(a, b)', 10]/" "$tmp/p5.yaml" >"$tmp/p5-quoted.yaml"
run "check: an expression with a comma, quoted" 0 "$MECH" check -q "$tmp/p5-quoted.yaml" && pass
sed 's/P: \[c \* c \/ a, 10\]/P: [1, 2, 3]/' "$tmp/p5.yaml" >"$tmp/p5-three.yaml"
if run "check: three numbers" 2 "$MECH" check -q "$tmp/p5-three.yaml"; then
    has_line "$tmp/err" "must be a list of two values \[x, y\], not of 3$" "three numbers: no hint"
fi
# a point of one link named in outputs is a coupler point, not a typo
sed -e 's/P: \[c \* c \/ a, 10\]/c: [30, 10]/' -e 's/points: \[A, B, P\]/points: [A, B, c]/' "$tmp/p5.yaml" >"$tmp/p5-out.yaml"
run "check: an output point on one link" 0 "$MECH" check -q "$tmp/p5-out.yaml" && pass
grep -q "joins nothing" "$tmp/err" && fail "an output point warned as joining nothing: $(cat "$tmp/err")" || pass
sed 's/points: \[A, B, c\]/points: [A, B]/' "$tmp/p5-out.yaml" >"$tmp/p5-lone.yaml"
if run "check: a lone point near C" 0 "$MECH" check -q "$tmp/p5-lone.yaml"; then
    has_line "$tmp/err" "point 'c' of link 'coupler' is on no other link and in no joint, so it joins nothing (did you mean 'C'" "lone point: still warned"
fi
# a dimension in the units the format knows: N*m*rad, not kg*m^2*rad/s^2
sed -e 's/^  b: 25 mm/  b: 25 mm\n  w: 2 N*m * 1 rad/' -e 's/P: \[c \* c \/ a, 10\]/P: [w, 10]/' "$tmp/p5.yaml" >"$tmp/p5-dim.yaml"
if run "check: a torque times an angle for a length" 2 "$MECH" check -q "$tmp/p5-dim.yaml"; then
    has_line "$tmp/err" "expected a length, got a quantity in N\*m\*rad$" "dimension in N*m*rad"
fi
# --stats under a time sweep names t
if run "solve --stats, a time sweep" 0 "$MECH" solve mechanisms/five-bar.yaml --stats -o /dev/null; then
    has_line "$tmp/err" "smallest rcond .* at t = .* s$" "--stats: at t"
fi

summary
