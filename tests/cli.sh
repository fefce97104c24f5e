#!/bin/sh
# tests/cli.sh: the `mech` command line: exit statuses and what it prints.
# Run from the repository root:  MECH=build/mech sh tests/cli.sh
# Prints one line per failure, then "cli: N passed, M failed"; exits 1 if
# anything failed.
MECH=${MECH:-build/mech}
if [ ! -x "$MECH" ]; then
    echo "cli: $MECH is not an executable (build it first, or set MECH)" >&2
    exit 2
fi

tmp=${TMPDIR:-/tmp}/mech-cli.$$
mkdir "$tmp" || exit 2
trap 'rm -rf "$tmp"' EXIT
trap 'exit 2' INT TERM HUP

passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

# run LABEL STATUS COMMAND...: run COMMAND with stdout in $tmp/out and stderr
# in $tmp/err; 0 when it exits with STATUS, else report a failure and 1.
run() {
    label=$1 want=$2
    shift 2
    "$@" >"$tmp/out" 2>"$tmp/err"
    status=$?
    if [ "$status" -ne "$want" ]; then
        fail "$label: exit status $status, expected $want (stderr: $(head -n 1 "$tmp/err"))"
        return 1
    fi
    return 0
}

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

echo "cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
