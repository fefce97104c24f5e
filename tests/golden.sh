#!/bin/sh
# tests/golden.sh: solve every mechanism in mechanisms/ and compare the result
# with its reviewed golden CSV in tests/golden/ (see tests/golden/README.md).
# Run from the repository root:  MECH=build/mech sh tests/golden.sh
# Regenerate the goldens with `make golden`, then review the diff by hand.
MECH=${MECH:-build/mech}
if [ ! -x "$MECH" ]; then
    echo "golden: $MECH is not an executable (build it first, or set MECH)" >&2
    exit 2
fi
tmp=${TMPDIR:-/tmp}/mech-golden.$$
mkdir "$tmp" || exit 2
trap 'rm -rf "$tmp"' EXIT
trap 'exit 2' INT TERM HUP

passed=0
failed=0
for f in mechanisms/*.yaml; do
    name=$(basename "$f" .yaml)
    golden=tests/golden/$name.csv
    if [ ! -f "$golden" ]; then
        failed=$((failed + 1))
        echo "FAIL: $f has no golden file $golden (make golden, then review it)"
        continue
    fi
    if ! "$MECH" solve "$f" -o "$tmp/$name.csv" 2>"$tmp/err"; then
        failed=$((failed + 1))
        echo "FAIL: mech solve $f: $(head -n 1 "$tmp/err")"
        continue
    fi
    if "$MECH" compare "$tmp/$name.csv" "$golden" >"$tmp/report" 2>&1; then
        passed=$((passed + 1))
    else
        failed=$((failed + 1))
        echo "FAIL: $f differs from $golden:"
        sed 's/^/    /' "$tmp/report"
    fi
done
echo "golden: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
