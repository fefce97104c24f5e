#!/bin/sh
# tests/signals.sh: the suites do not depend on the signal dispositions
# they inherit (tests/lib.sh runs each again under `tests/sigexec.c
# default`). Under a parent that ignores SIGTERM, SIGHUP and SIGPIPE and
# blocks SIGINT and SIGQUIT (`sigexec hostile`), and under nohup, a suite's
# commands start with no signal ignored or blocked, and tests/files.sh (its
# fast subset) passes: mech killed by SIGTERM, SIGHUP or SIGINT while it
# writes dies of that signal and leaves no temporary file (not under
# MECH_QUICK=1, which runs the rest).
# Run from the repository root:  MECH=build/mech sh tests/signals.sh
NAME=signals . tests/lib.sh

# bits: of the /proc/PID/status on standard input, which of SIGHUP,
# SIGINT, SIGQUIT, SIGPIPE and SIGTERM are ignored and which blocked, as
# the masks' bits (Linux numbers 1, 2, 3, 13, 15: bit n - 1; the C
# library's own 32 and 33, which no program can reset, are left out)
bits() {
    set -- $(awk '$1 == "SigIgn:" { i = $2 } $1 == "SigBlk:" { b = $2 } END { print i, b }')
    printf '%04x %04x\n' $((0x${1#"${1%????}"} & 0x5007)) $((0x${2#"${2%????}"} & 0x5007))
}
# masks COMMAND...: the bits COMMAND starts with
masks() { "$@" cat /proc/self/status | bits; }
hostile="5001 0006"
none="0000 0000"

if [ ! -r /proc/self/status ]; then
    echo "signals: no /proc/self/status; skipped"
    summary
    exit
fi

# the launcher does what it says (else the rest proves nothing)
got=$(masks "$SIGEXEC" hostile)
[ "$got" = "$hostile" ] && pass || fail "sigexec hostile: ignored, blocked $got, expected $hostile"
got=$(masks "$SIGEXEC" hostile "$SIGEXEC" default)
[ "$got" = "$none" ] && pass || fail "sigexec default under hostile: ignored, blocked $got, expected none"

# a suite (sourcing tests/lib.sh) started by dash or bash under a hostile
# parent or nohup: what its commands inherit (dash clears a blocked mask
# itself, bash does not)
printf 'NAME=probe . tests/lib.sh\ncat /proc/self/status\n' >"$tmp/probe.sh"
for shell in sh bash; do
    command -v $shell >/dev/null 2>&1 || continue
    got=$("$SIGEXEC" hostile $shell "$tmp/probe.sh" | bits)
    [ "$got" = "$none" ] && pass || fail "a suite run by $shell under a hostile parent: its commands inherit $got"
    if command -v nohup >/dev/null 2>&1; then
        got=$(nohup $shell "$tmp/probe.sh" 2>/dev/null </dev/null | bits)
        [ "$got" = "$none" ] && pass || fail "a suite run by $shell under nohup: its commands inherit $got"
    fi
done

# the signal tests of tests/files.sh under the hostile parent
files_hostile() {
    if MECH_QUICK=1 "$SIGEXEC" hostile sh tests/files.sh >"$tmp/files.out" 2>&1; then
        pass
    else
        fail "tests/files.sh (MECH_QUICK=1) under a hostile parent:"
        grep -e '^FAIL' -e '^files:' "$tmp/files.out" | sed 's/^/    /'
    fi
}
full files_hostile

summary
