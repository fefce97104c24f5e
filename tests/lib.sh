# tests/lib.sh: what the shell tests share, sourced after setting NAME (the
# tag of their summary line) from the repository root:
#   NAME=cli . tests/lib.sh
# It checks $MECH, runs the suite again with the default signal dispositions
# (below), makes $tmp (removed on exit), and defines pass, fail, run,
# has_line and summary ("NAME: N passed, M failed"; status 1 on a failure).
# MECH_QUICK=1 (make check) asks a suite for its fast subset: fewer files
# and variants, the same kinds of checks.
MECH=${MECH:-build/mech}
if [ ! -x "$MECH" ]; then
    echo "$NAME: $MECH is not an executable (build it first, or set MECH)" >&2
    exit 2
fi

# Every suite starts with each signal at its default action and none
# blocked, whatever its parent left (nohup, a CI runner that ignores
# SIGTERM): a suite that kills mech must see it die. A shell can neither
# trap nor reset a signal ignored when it started, so the suite runs itself
# again under tests/sigexec.c (built beside $MECH when missing); exec keeps
# the pid, which marks the suite as reset (a suite it starts resets again).
SIGEXEC=${SIGEXEC:-$(dirname "$MECH")/sigexec}
if [ "${MECH_SIGNALS_RESET:-}" != $$ ]; then
    if [ ! -x "$SIGEXEC" ]; then
        ${CC:-cc} -o "$SIGEXEC.$$" tests/sigexec.c && mv -f "$SIGEXEC.$$" "$SIGEXEC" || exit 2
    fi
    MECH_SIGNALS_RESET=$$ exec "$SIGEXEC" default sh "$0" "$@"
fi

tmp=${TMPDIR:-/tmp}/mech-$NAME.$$
mkdir "$tmp" || exit 2
trap 'rm -rf "$tmp"' EXIT
# the compiled solvers of --jit cached in the suite's own directory: no
# suite reads or fills the user's cache (docs/codegen.md)
MECH_CACHE_DIR=$tmp/cache
export MECH_CACHE_DIR
# the suites compare the interpreter with the compiled solver: plain runs
# stay interpreted (--engine auto would load what --jit cached); tests/jit.sh
# turns it on where it checks the automatic choice
MECH_JIT_AUTO=off
export MECH_JIT_AUTO
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

# full COMMAND...: a check of the full tier alone, skipped under MECH_QUICK=1
full() { [ -n "${MECH_QUICK:-}" ] || "$@"; }

summary() {
    echo "$NAME: $passed passed, $failed failed"
    [ "$failed" -eq 0 ]
}
