# tests/lib.sh: what the shell tests share, sourced after setting NAME (the
# tag of their summary line) from the repository root:
#   NAME=cli . tests/lib.sh
# It checks $MECH, makes $tmp (removed on exit), and defines pass, fail, run,
# has_line and summary ("NAME: N passed, M failed"; status 1 on a failure).
MECH=${MECH:-build/mech}
if [ ! -x "$MECH" ]; then
    echo "$NAME: $MECH is not an executable (build it first, or set MECH)" >&2
    exit 2
fi

tmp=${TMPDIR:-/tmp}/mech-$NAME.$$
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

# has_line FILE PATTERN LABEL: pass when a line of FILE matches PATTERN.
has_line() {
    if grep -q -- "$2" "$1"; then pass; else fail "$3: no line matching '$2' in $(head -c 300 "$1")"; fi
}

summary() {
    echo "$NAME: $passed passed, $failed failed"
    [ "$failed" -eq 0 ]
}
