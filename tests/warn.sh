#!/bin/sh
# tests/warn.sh: the checks of a suspect assembly (docs/solver.md section 9,
# src/solve/assembly.c). Each warning fires on a file built to trigger it
# (tests/warn/), with its place and words, and is an error under --strict
# (solve, check, batch); the same mechanisms with guesses that choose the
# meant assembly are silent and their rows are checked against closed
# forms; every shipped file (mechanisms/, tests/truths/) is silent.
NAME=warn . tests/lib.sh

W=tests/warn
KINDS='far from the guess|stays on a ground point|does not slide|is flat over|moves none'

# ---- the toggle press of issue 28: the lower link folded back onto the upper
run "toggle: solve" 0 "$MECH" solve $W/toggle-press.yaml -o "$tmp/t.csv" && pass
has_line "$tmp/err" "toggle-press.yaml:31:14: warning: point 'D' of link 'ram' stays on a ground point 'O' over the whole sweep" "toggle: D on O"
has_line "$tmp/err" "toggle-press.yaml:36:5: warning: slider 's_D' (link 'ram' on 'ground') does not slide" "toggle: still slider"
has_line "$tmp/err" "warning: loop 2 ('lower', 'upper') is flat over the whole sweep" "toggle: flat loop"
# the rows say the same: D.y is 0 (on O) at every row, to rounding
awk -F, 'NR > 1 && ($3 > 1e-12 || $3 < -1e-12) { bad = 1 } END { exit bad }' "$tmp/t.csv" &&
    pass || fail "toggle: D.y is not 0 in every row"
# only the ram among the outputs: none of them moves
run "toggle: still outputs" 0 "$MECH" solve $W/toggle-press.yaml --outputs D,s_D -o /dev/null && pass
has_line "$tmp/err" "toggle-press.yaml:44:3: warning: the driver's motion moves none of the outputs" "toggle: still outputs"
run "toggle: --strict" 1 "$MECH" solve $W/toggle-press.yaml --strict -o "$tmp/strict.csv" && pass
has_line "$tmp/err" "toggle-press.yaml:31:14: error: point 'D'" "toggle: --strict error"
has_line "$tmp/err" "mech solve: --strict: the assembly is suspect (3 findings); no output file written" "toggle: --strict summary"
[ -e "$tmp/strict.csv" ] && fail "toggle: --strict wrote a file" || pass
run "toggle: check" 0 "$MECH" check -q $W/toggle-press.yaml && pass
[ "$(grep -Ec "$KINDS" "$tmp/err")" -eq 3 ] && pass || fail "toggle: check: $(cat "$tmp/err")"
run "toggle: check --strict" 1 "$MECH" check -q --strict $W/toggle-press.yaml && pass

# the same press with guesses for the rod and the toggle: silent, and the
# ram where the toggle puts it: D = (0, K.y - sqrt(100^2 - K.x^2)) mm
run "toggle fixed" 0 "$MECH" solve $W/toggle-press-fixed.yaml --outputs D,K -o "$tmp/f.csv" --strict && pass
[ -s "$tmp/err" ] && fail "toggle fixed: not silent: $(head -n 1 "$tmp/err")" || pass
awk -F, 'NR > 1 { want = $9 - sqrt(0.01 - $8 * $8); e = $3 - want; if (e < 0) e = -e;
                  if (e > 1e-12 || $2 > 1e-12 || $2 < -1e-12) bad = 1; if ($3 > -0.19) bad = 1 }
         END { exit bad }' "$tmp/f.csv" && pass || fail "toggle fixed: the ram is not under the knee"

# ---- the steering of issue 28: the left knuckle 105 deg off its guess
run "steering" 0 "$MECH" solve $W/steering.yaml -o "$tmp/s.csv" && pass
has_line "$tmp/err" "steering.yaml:39:11: warning: link 'knuckle_l' is at 15.0 deg in the first position, far from the guess -90.0 deg (105 deg off)" "steering: far from guess"
[ "$(wc -l <"$tmp/err")" -eq 1 ] && pass || fail "steering: more than one warning: $(cat "$tmp/err")"
# the knuckle's other branch: the arm's end AL = (-600, -150) mm mirrored
# about the line from KL (-600, 0) to RL (-404.5, -150) (about -37.5 deg, so
# the knuckle at about 2 (-37.5) + 90 = 15 deg)
awk -F, 'NR == 2 { ux = 195.5; uy = -150; n = sqrt(ux * ux + uy * uy); ux /= n; uy /= n;
                   px = 0; py = -150; t = px * ux + py * uy;
                   mx = 2 * t * ux - px; my = 2 * t * uy - py; want = atan2(my, mx);
                   d = $2 - want; exit !(d < 1e-12 && d > -1e-12) }' "$tmp/s.csv" &&
    pass || fail "steering: knuckle_l not at 15 deg at the first row: $(sed -n 2p "$tmp/s.csv")"
# --outputs knuckle_r: the left side is not solved, so neither checked;
# --stats says the checks over the sweep did not run
run "steering: partial" 0 "$MECH" solve $W/steering.yaml --outputs knuckle_r --stats -o /dev/null && pass
has_line "$tmp/err" "assembly checks    the guesses only: the outputs need 2 of 4 unknowns" "steering: checks skipped said"
grep -Eq "$KINDS" "$tmp/err" && fail "steering: partial: a check ran on links not solved" || pass
run "steering: --strict" 1 "$MECH" solve $W/steering.yaml --strict && pass
run "steering fixed" 0 "$MECH" solve $W/steering-fixed.yaml --strict -o "$tmp/sf.csv" && pass
awk -F, 'NR == 2 { d = $2 * 180 / 3.14159265358979 + 90; exit !(d < 1e-9 && d > -1e-9) }' "$tmp/sf.csv" &&
    pass || fail "steering fixed: knuckle_l not at -90 deg: $(sed -n 2p "$tmp/sf.csv")"

# ---- batch: --strict fails the suspect files, the others stay ok
run "batch --strict" 1 "$MECH" batch -q --strict $W/steering.yaml $W/steering-fixed.yaml && pass
has_line "$tmp/out" "^steering  *FAILED" "batch: steering failed"
has_line "$tmp/out" "^steering-fixed  *ok" "batch: steering-fixed ok"
run "batch" 0 "$MECH" batch -q $W/steering.yaml && pass

# ---- sweep: a variant that solved with a suspect assembly says so
sed -e 's|^units: {length: mm, angle: deg}|units: {length: mm, angle: deg}\nparameters: {r: 20 mm}|' \
    -e 's|points: {P: \[0, 0\], A: \[20, 0\]}|points: {P: [0, 0], A: [r, 0]}|' $W/toggle-press.yaml >"$tmp/tpr.yaml"
run "sweep" 0 "$MECH" sweep "$tmp/tpr.yaml" --vary r=18mm:22mm:2 -q && pass
has_line "$tmp/err" "^variant 1: r=22 mm" "sweep: the variant named"
[ "$(grep -c "stays on a ground point 'O'" "$tmp/err")" -eq 2 ] && pass || fail "sweep: $(cat "$tmp/err")"
has_line "$tmp/out" "^1,0.022,ok,73" "sweep: the variant solved"

# ---- every shipped file is silent (mech check assembles every link)
for f in mechanisms/*.yaml tests/truths/*.yaml; do
    "$MECH" check -q --strict "$f" >/dev/null 2>"$tmp/err"
    st=$?
    if [ "$st" -ne 0 ] || grep -Eq "$KINDS" "$tmp/err"; then
        fail "$f: not silent (exit $st): $(head -n 1 "$tmp/err")"
    else
        pass
    fi
done

summary
