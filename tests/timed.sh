#!/bin/sh
# tests/timed.sh: the time each suite of make test and make check takes
# (docs/testing.md): wall seconds, and the CPU seconds (user and system) of
# the suite's processes, which other work on the machine does not inflate.
# LOG holds a line "NAME WALL CPU STATUS" per suite run.
#   sh tests/timed.sh LOG begin             start LOG afresh
#   sh tests/timed.sh LOG NAME COMMAND...   run COMMAND, print "time: NAME ...",
#                                           add it to LOG; COMMAND's exit status
#                                           (on a failure the table so far too)
#   sh tests/timed.sh LOG table             the table of LOG, with the totals
log=$1
shift

table() {
    awk '{ name[NR] = $1; wall[NR] = $2; cpu[NR] = $3; st[NR] = $4; tw += $2; tc += $3 }
        END {
            printf "%-14s %8s %6s %8s\n", "suite", "wall s", "share", "cpu s"
            for (i = 1; i <= NR; i++)
                printf "%-14s %8.1f %5.0f%% %8.1f%s\n", name[i], wall[i], (tw > 0 ? 100 * wall[i] / tw : 0),
                       cpu[i], (st[i] == 0 ? "" : "  FAILED (exit " st[i] ")")
            printf "%-14s %8.1f %6s %8.1f\n", "total", tw, "", tc
        }' "$log"
}

case $1 in
begin) : >"$log" ;;
table) table ;;
*)
    name=$1
    shift
    start=$(date +%s.%N)
    "$@"
    status=$?
    # the shell's `times`: its own user and system time, then its children's
    # (no subshell: a forked one would count none of them)
    times >"$log.cpu"
    wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
    cpu=$(awk 'function s(t) { split(t, p, "m"); return p[1] * 60 + p[2] }
        NR == 2 { printf "%.1f", s($1) + s($2) }' "$log.cpu")
    rm -f "$log.cpu"
    echo "$name $wall $cpu $status" >>"$log"
    if [ $status -eq 0 ]; then
        echo "time: $name $wall s (cpu $cpu s)"
    else
        echo "time: $name $wall s (cpu $cpu s), FAILED (exit $status)"
        table
    fi
    exit $status
    ;;
esac
