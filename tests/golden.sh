#!/bin/sh
# tests/golden.sh: solve every mechanism in mechanisms/ with `mech batch` and
# compare each result with its reviewed golden CSV in tests/golden/ (see
# tests/golden/README.md). Run from the repository root:
#   MECH=build/mech sh tests/golden.sh
# Regenerate the goldens with `make golden`, then review the diff by hand.
NAME=golden . tests/lib.sh

"$MECH" batch -j 2 --golden tests/golden mechanisms/*.yaml >"$tmp/table" 2>"$tmp/err"
status=$?
passed=$(grep -c ' ok .* match$' "$tmp/table")
total=$(ls mechanisms/*.yaml | wc -l)
failed=$((total - passed))
if [ "$status" -ne 0 ] || [ "$failed" -ne 0 ]; then
    echo "FAIL: mech batch --golden tests/golden exited $status:"
    grep -v ' ok .* match$' "$tmp/table" | sed 's/^/    /'
    sed 's/^/    /' "$tmp/err" | head -n 60
    [ "$failed" -gt 0 ] || failed=1
fi
summary
