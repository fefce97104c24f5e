# tests/recipe.sh: what the recipe tests (tests/parallel, tests/slurm) share,
# sourced after tests/lib.sh. recipe NAME prints the fenced block that
# follows "<!-- recipe NAME -->" in docs/batch.md, so the tests run the
# recipes exactly as the documentation writes them. scratch makes $work, a
# directory holding build/ (the directory of $MECH) and mechanisms/, the
# recipes' working directory. kill_shard K_PATTERN kills the mech process of
# this test whose arguments match (found by its working directory: never
# another user's process).
repo=$(pwd)
recipe() {
    awk -v want="<!-- recipe $1 -->" '
        $0 == want { found = 1; next }
        found && /^```/ { if (inside) exit; inside = 1; next }
        inside { print }' "$repo/docs/batch.md"
}

scratch() {
    work=$tmp/work
    mkdir -p "$work"
    ln -s "$(cd "$(dirname "$MECH")" && pwd)" "$work/build"
    ln -s "$repo/mechanisms" "$work/mechanisms"
}

# The pid of the mech process running in $work whose command line has $1.
shard_pid() {
    for p in $(pgrep -f -- "$1"); do
        [ "$(cat /proc/$p/comm 2>/dev/null)" = mech ] || continue
        [ "$(readlink /proc/$p/cwd 2>/dev/null)" = "$(cd "$work" && pwd -P)" ] && echo "$p" && return 0
    done
    return 1
}

# kill_running_shard M LIMIT [PATTERN]: the first shard K of M whose
# out/sweep.K.csv.partial (or the file PATTERN names, %s for K) is there
# with its head (manifest and header: the shard runs; rows come in blocks up
# to a second apart, so a short shard may show none before its end) and
# whose process is still there (a short shard can end between the two looks;
# another is taken then) gets SIGTERM; prints "K PID", or nothing when no
# shard was seen running within LIMIT seconds.
kill_running_shard() {
    m=$1 limit=$2 waited=0 pattern=${3:-sweep.%s.csv.partial}
    while [ "$waited" -lt $((limit * 20)) ]; do
        for k in $(seq 0 $((m - 1))); do
            # shellcheck disable=SC2059
            f=$work/out/$(printf "$pattern" "$k")
            [ -f "$f" ] && [ "$(wc -l <"$f")" -ge 2 ] || continue
            if p=$(shard_pid "--shard $k/$m "); then
                kill -TERM "$p" && echo "$k $p" && return 0
            fi
        done
        sleep 0.05
        waited=$((waited + 1))
    done
    return 1
}

# the table less its timing column (us/step)
untimed() { awk '{ $5 = ""; print }' "$1"; }
