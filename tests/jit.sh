#!/bin/sh
# tests/jit.sh: `mech solve --jit` held to the interpreter where the data
# go wrong (docs/codegen.md, section "mech solve --jit"; issue 32 points 1
# and 6):
#  - files whose rows hold a value that is not finite (a load's log of a
#    negative number, a driver speed of 1e160 rad/s, overflowing masses,
#    accelerations, springs, a law of time): the generated code, compiled
#    and used (a compiler that logs its runs, no fallback note), gives the
#    interpreter's exit status (1), its error naming the row and column, its
#    standard error byte for byte and the same rows written (or none);
#  - the compile interrupted: SIGTERM, SIGINT or SIGHUP while $CC runs
#    removes the private directory in $TMPDIR and stops the compiler's whole
#    process group before mech dies of the signal;
#  - $CC is split on blanks, not given to a shell.
# Run from the repository root:  MECH=build/mech sh tests/jit.sh
NAME=jit . tests/lib.sh
CC=${CC:-cc}
mkdir -p "$tmp/jt"
printf '#!/bin/sh\necho run >>"%s/cc.log"\nexec %s "$@"\n' "$tmp" "$CC" >"$tmp/cc-log"
chmod +x "$tmp/cc-log"

# ---- values that are not finite: the interpreter's check, in --jit too ----
# nonfinite LABEL FILE [OPTIONS]: the interpreter must stop with its
# "not a finite number" error (exit 1); --jit, compiled and used, the same
# exit status, standard error and output file (or none)
nonfinite() {
    label=$1 file=$2
    shift 2
    rm -f "$tmp/interp.csv" "$tmp/jit.csv" "$tmp/cc.log"
    "$MECH" solve "$file" -q "$@" -o "$tmp/interp.csv" 2>"$tmp/interp.err"
    want=$?
    if [ "$want" != 1 ] || ! grep -q "not a finite number" "$tmp/interp.err"; then
        fail "$label: the interpreter exits $want without the non-finite error: $(head -n 1 "$tmp/interp.err")"
        return
    fi
    # no cache: the same source under other options must compile to be seen
    MECH_JIT_CACHE=off TMPDIR=$tmp/jt CC=$tmp/cc-log "$MECH" solve "$file" -q --jit "$@" \
        -o "$tmp/jit.csv" 2>"$tmp/jit.err"
    got=$?
    if [ "$got" != "$want" ]; then
        fail "$label: --jit exits $got, the interpreter $want: $(head -n 1 "$tmp/jit.err")"
    elif ! cmp -s "$tmp/interp.err" "$tmp/jit.err"; then
        fail "$label: --jit's stderr '$(head -n 1 "$tmp/jit.err")', the interpreter's '$(head -n 1 "$tmp/interp.err")'"
    elif [ -e "$tmp/interp.csv" ] && ! cmp -s "$tmp/interp.csv" "$tmp/jit.csv"; then
        fail "$label: --jit wrote other rows than the interpreter"
    elif [ ! -e "$tmp/interp.csv" ] && [ -e "$tmp/jit.csv" ]; then
        fail "$label: --jit wrote rows where the interpreter wrote none"
    elif [ ! -s "$tmp/cc.log" ]; then
        fail "$label: --jit did not compile (the interpreter solved it)"
    else
        pass
    fi
}

# the four-bar with a crank load: LOAD is the load's line
fourbar_load() {
    sed "s|^outputs:|loads:\n  - $1\noutputs:\n  forces: true|" mechanisms/fourbar.yaml
}
# the issue's two reproducers: a load log(A.x / 1 m), NaN from 91 deg on,
# and a driver speed of 1e160 rad/s, whose rates overflow at the first row
fourbar_load '{torque: "1 N*m * log(A.x / (1 m))", link: crank}' >"$tmp/log.yaml"
sed 's|speed: 10 rad/s|speed: 1e160 rad/s|' mechanisms/fourbar.yaml >"$tmp/speed.yaml"
# more: the square root of a negative number (from 181 deg), 1 / 0 at the
# first row (+inf), exp overflowing, a huge acceleration, an overflowing
# mass, an overflowing spring
fourbar_load '{torque: "1 N*m * sqrt(A.y / (1 m))", link: crank}' >"$tmp/sqrt.yaml"
fourbar_load '{torque: "1 N*m / (A.y / (1 m))", link: crank}' >"$tmp/div.yaml"
fourbar_load '{torque: "1 N*m * exp(crank.omega * (100 s) / (1 rad))", link: coupler}' \
    >"$tmp/exp.yaml"
sed -e 's|speed: 10 rad/s|speed: 10 rad/s\n  acceleration: 1e300 rad/s^2|' \
    -e 's|inertia: 2e-6 kg\*m^2|inertia: 1e10 kg*m^2|' mechanisms/fourbar.yaml >"$tmp/accel.yaml"
sed -e 's|mass: 0.05 kg|mass: 1e308 kg|' -e 's|speed: 10 rad/s|speed: 100 rad/s|' \
    mechanisms/fourbar.yaml >"$tmp/mass.yaml"
sed 's|damping: 20 N\*s/m|damping: 1e308 N*s/m|' mechanisms/spring-slider-crank.yaml >"$tmp/spring.yaml"
grep -q 'damping: 1e308' "$tmp/spring.yaml" && pass || fail "spring.yaml: no damping replaced"
# with pin friction (the conveyor): the load's NaN inside the friction iteration
sed "s|^loads:|loads:\n  - {torque: \"1 N*m * log(B.y / (1 m))\", link: rocker4}|" \
    mechanisms/conveyor.yaml >"$tmp/friction.yaml"
grep -q 'log(B.y' "$tmp/friction.yaml" && pass || fail "friction.yaml: no load added"
# a law of time whose speed squared overflows (the five-bar's drivers)
sed 's|angle: "90 deg + 360 deg/s \* t"|angle: "90 deg + 1e200 rad/s * t"|' mechanisms/five-bar.yaml \
    >"$tmp/law.yaml"
grep -q '1e200 rad/s' "$tmp/law.yaml" && pass || fail "law.yaml: no law replaced"
# MECH_QUICK=1 (make check): one file of each kind (a load, a law of time,
# the forces); make test: every one
cases="log speed sqrt div exp spring friction law"
[ -n "$MECH_QUICK" ] && cases="log law"
for f in $cases; do
    nonfinite "$f" "$tmp/$f.yaml"
done
nonfinite "mass --forces" "$tmp/mass.yaml" --forces
if [ -z "$MECH_QUICK" ]; then
    nonfinite "accel --forces" "$tmp/accel.yaml" --forces
    nonfinite "log --forces --friction off" "$tmp/log.yaml" --forces --friction off
    nonfinite "speed --range" "$tmp/speed.yaml" --from 10 --to 20 --steps 5
fi
[ -z "$(ls "$tmp/jt")" ] && pass || fail "solve --jit left files in TMPDIR: $(ls "$tmp/jt")"

# ---- $CC: split on blanks, never given to a shell ----
printf '#!/bin/sh\necho "$*" >"%s/cc-args.log"\nexec %s "$@"\n' "$tmp" "$CC" >"$tmp/cc-args"
chmod +x "$tmp/cc-args"
rm -f "$tmp/cc-args.log"
TMPDIR=$tmp/jt CC="  $tmp/cc-args  -O1	-g " "$MECH" solve mechanisms/fourbar.yaml -q --jit \
    -o "$tmp/flags.csv" 2>"$tmp/flags.err"
case $(cat "$tmp/cc-args.log" 2>/dev/null) in
"-O1 -g -std=c11 -O2 -fPIC -shared -o $tmp/jt/mech-jit."*"/jit.so $tmp/jt/mech-jit."*"/jit.c -lm")
    ! grep -q 'note: --jit' "$tmp/flags.err" && pass || fail "CC with flags: $(cat "$tmp/flags.err")" ;;
*) fail "CC with flags: the compiler's arguments '$(cat "$tmp/cc-args.log" 2>/dev/null)'" ;;
esac
# shell syntax in $CC is a file name, not a command
CC="$tmp/cc-log; touch $tmp/shell-ran" TMPDIR=$tmp/jt "$MECH" solve mechanisms/fourbar.yaml -q \
    --jit -o "$tmp/shell.csv" 2>"$tmp/shell.err"
[ ! -e "$tmp/shell-ran" ] && pass || fail "CC went through a shell"
has_line "$tmp/shell.err" "note: --jit: no C compiler ran ('$tmp/cc-log;': No such file or directory)" \
    "CC with shell syntax"
cmp -s "$tmp/shell.csv" "$tmp/flags.csv" && pass || fail "CC with shell syntax: not the interpreter's table"
[ -z "$(ls "$tmp/jt")" ] && pass || fail "solve --jit left files in TMPDIR: $(ls "$tmp/jt")"

# ---- a signal during the compile ----
# a compiler that takes its time (IGNORE: it and its child ignore SIGTERM):
# its pid (its process group's) and its child's in slow.pid and child.pid
slow_cc() {
    printf '#!/bin/sh\n%s\necho $$ >"%s/slow.pid"\nsleep 60 &\necho $! >"%s/child.pid"\nwait\nexec %s "$@"\n' \
        "$1" "$tmp" "$tmp" "$CC" >"$tmp/cc-slow"
    chmod +x "$tmp/cc-slow"
}
# gone PID: the process has ended (within 5 s: an orphan is reaped by init)
gone() {
    i=0
    while kill -0 "$1" 2>/dev/null; do
        [ $i -ge 50 ] && return 1
        sleep 0.1
        i=$((i + 1))
    done
}
# interrupt SIG STATUS: SIG to mech solve --jit while cc-slow runs; mech
# dies of it (STATUS), the private directory is gone, and so is every
# process of the compiler's group (the shell and its sleep), no file written
default_int=
env --default-signal=INT true 2>/dev/null && default_int=--default-signal=INT
interrupt() {
    sig=$1 want=$2
    rm -rf "$tmp/slow.pid" "$tmp/child.pid" "$tmp/int.csv" "$tmp/jk"
    mkdir "$tmp/jk"
    # a background job ignores SIGINT unless told otherwise (env)
    TMPDIR=$tmp/jk CC=$tmp/cc-slow env $default_int "$MECH" solve mechanisms/fourbar.yaml -q \
        --jit -o "$tmp/int.csv" 2>"$tmp/int.err" &
    mpid=$!
    i=0
    while [ ! -s "$tmp/child.pid" ] && [ $i -lt 300 ]; do
        sleep 0.1
        i=$((i + 1))
    done
    if [ ! -s "$tmp/child.pid" ]; then
        kill -KILL $mpid 2>/dev/null
        fail "SIG$sig: the slow compiler did not start in 30 s: $(cat "$tmp/int.err")"
        return
    fi
    [ -n "$(ls "$tmp/jk")" ] && pass || fail "SIG$sig: no private directory while compiling"
    kill -$sig $mpid
    wait $mpid 2>/dev/null  # not the shell's "Terminated"
    status=$?
    [ "$status" = "$want" ] && pass || fail "SIG$sig: mech exited $status, expected $want (died of it)"
    [ -z "$(ls "$tmp/jk")" ] && pass || fail "SIG$sig: left in TMPDIR: $(ls -R "$tmp/jk")"
    gone "$(cat "$tmp/slow.pid")" && gone "$(cat "$tmp/child.pid")" && pass ||
        fail "SIG$sig: the compiler's processes still run: $(ps -o pid,pgid,args -p "$(cat "$tmp/slow.pid")" -p "$(cat "$tmp/child.pid")")"
    [ ! -e "$tmp/int.csv" ] && pass || fail "SIG$sig: an output was written"
}
slow_cc ''
interrupt TERM 143
[ -z "$MECH_QUICK" ] && interrupt HUP 129
if [ -n "$MECH_QUICK" ]; then
    :  # SIGINT and SIGHUP take the same path as SIGTERM (make test runs them)
elif [ -n "$default_int" ]; then
    interrupt INT 130
else
    echo "jit: SIGINT not tested (env --default-signal needs coreutils 8.31)"
fi
# a compiler that ignores SIGTERM: SIGKILL a second later
slow_cc "trap '' TERM"
interrupt TERM 143

# ---- the cache of compiled solvers (docs/codegen.md) ----
# a second run of the same file loads the object compiled by the first (no
# compiler runs), the same table byte for byte; a corrupted, planted or
# foreign entry is never loaded; the directory must be the user's alone
cdir=$tmp/cc-cache
jitrun() {  # jitrun OUT: --jit --stats on the four-bar through the logging compiler
    rm -f "$tmp/cc.log"
    MECH_CACHE_DIR=$cdir TMPDIR=$tmp/jt CC=$tmp/cc-log "$MECH" solve mechanisms/fourbar.yaml -q \
        --jit --stats -o "$1" 2>"$tmp/cache.err"
}
"$MECH" solve mechanisms/fourbar.yaml -q -o "$tmp/c-interp.csv"
jitrun "$tmp/c1.csv" && [ -s "$tmp/cc.log" ] && grep -q "solver .*compiled in .*stored in the cache $cdir/jit" "$tmp/cache.err" &&
    cmp -s "$tmp/c1.csv" "$tmp/c-interp.csv" && pass ||
    fail "cache: the first run did not compile and store: $(grep solver "$tmp/cache.err")"
[ "$(stat -c %a "$cdir/jit")" = 700 ] && pass || fail "cache: $cdir/jit has mode $(stat -c %a "$cdir/jit")"
jitrun "$tmp/c2.csv" && [ ! -e "$tmp/cc.log" ] && grep -q "solver .*from the cache" "$tmp/cache.err" &&
    cmp -s "$tmp/c2.csv" "$tmp/c-interp.csv" && pass ||
    fail "cache: the second run compiled again, or another table: $(grep solver "$tmp/cache.err")"
so=$(ls "$cdir"/jit/*.so)
# a corrupted object (one byte changed, same size): compiled again, replaced
printf 'X' | dd of="$so" bs=1 seek=100 conv=notrunc 2>/dev/null
jitrun "$tmp/c3.csv" && [ -s "$tmp/cc.log" ] && cmp -s "$tmp/c3.csv" "$tmp/c-interp.csv" && pass ||
    fail "cache: a corrupted object was loaded, or the table differs: $(grep solver "$tmp/cache.err")"
jitrun "$tmp/c4.csv" && [ ! -e "$tmp/cc.log" ] && pass || fail "cache: the replaced entry is not used"
# a truncated object
: >"$so"
jitrun "$tmp/c5.csv" && [ -s "$tmp/cc.log" ] && cmp -s "$tmp/c5.csv" "$tmp/c-interp.csv" && pass ||
    fail "cache: a truncated object was loaded"
# a key edited (another mechanism's source under this name): not a hit
key=$(ls "$cdir"/jit/*.key)
sed -i 's/^#define NX .*/#define NX 1/' "$key"
jitrun "$tmp/c6.csv" && [ -s "$tmp/cc.log" ] && pass || fail "cache: an edited key was taken as a hit"
# an entry others may write, or a symbolic link: not used
chmod 666 "$so"
jitrun "$tmp/c7.csv" && [ -s "$tmp/cc.log" ] && cmp -s "$tmp/c7.csv" "$tmp/c-interp.csv" && pass ||
    fail "cache: an object writable by others was loaded"
jitrun "$tmp/c8.csv"
cp "$so" "$tmp/planted.so" && rm -f "$so" && ln -s "$tmp/planted.so" "$so"
jitrun "$tmp/c9.csv" && [ -s "$tmp/cc.log" ] && pass || fail "cache: an object behind a symbolic link was loaded"
if [ "$(id -u)" = 0 ] && id nobody >/dev/null 2>&1; then
    jitrun "$tmp/c10.csv"
    so=$(ls "$cdir"/jit/*.so)
    chown nobody "$so"
    jitrun "$tmp/c11.csv" && [ -s "$tmp/cc.log" ] && pass || fail "cache: an object of another user was loaded"
fi
# the directory open to others: not used (said in --stats), the table right
chmod 755 "$cdir/jit"
jitrun "$tmp/c12.csv" && [ -s "$tmp/cc.log" ] && grep -q "not cached: .*not a directory of this user's alone" "$tmp/cache.err" &&
    cmp -s "$tmp/c12.csv" "$tmp/c-interp.csv" && pass ||
    fail "cache: a directory open to others was used: $(grep solver "$tmp/cache.err")"
chmod 700 "$cdir/jit"
# another compiler command: another entry; the bound keeps the newest only
rm -rf "$cdir"
jitrun "$tmp/c13.csv"
rm -f "$tmp/cc.log"
MECH_JIT_CACHE_MB=0.01 MECH_CACHE_DIR=$cdir TMPDIR=$tmp/jt CC="$tmp/cc-log -g0" "$MECH" solve \
    mechanisms/fourbar.yaml -q --jit -o "$tmp/c14.csv" 2>"$tmp/cache.err"
[ -s "$tmp/cc.log" ] && [ "$(ls "$cdir"/jit/*.key | wc -l)" = 1 ] && cmp -s "$tmp/c14.csv" "$tmp/c-interp.csv" && pass ||
    fail "cache: another command was a hit, or the bound kept $(ls "$cdir"/jit/*.key | wc -l) entries"
# MECH_JIT_CACHE=off: compiled, nothing read or stored
rm -rf "$cdir"
MECH_JIT_CACHE=off jitrun "$tmp/c15.csv" && [ -s "$tmp/cc.log" ] && [ ! -e "$cdir" ] &&
    grep -q "not cached: MECH_JIT_CACHE=off" "$tmp/cache.err" && pass || fail "cache: MECH_JIT_CACHE=off still used it"
[ -z "$(ls "$tmp/jt")" ] && pass || fail "cache: files left in TMPDIR: $(ls "$tmp/jt")"


# ---- --engine auto: compiled by itself where it pays off ------------------
# autorun ROWS OUT [OPTIONS]: mech solve (no --jit) with MECH_JIT_AUTO_ROWS=ROWS,
# the automatic choice on, through the logging compiler, --stats in auto.err
adir=$tmp/auto-cache
autorun() {
    rows=$1 out=$2
    shift 2
    rm -f "$tmp/cc.log"
    env -u MECH_JIT_AUTO MECH_JIT_AUTO_ROWS="$rows" MECH_CACHE_DIR="$adir" TMPDIR=$tmp/jt \
        CC=$tmp/cc-log "$MECH" solve mechanisms/fourbar.yaml -q --stats "$@" -o "$out" 2>"$tmp/auto.err"
}
# 361 rows, fewer than a hundredth of 100 000: interpreted, no compiler run
autorun 100000 "$tmp/a1.csv" && [ ! -e "$tmp/cc.log" ] &&
    grep -q "solver .*interpreted (auto: 361 rows, fewer than the 100000 from which compiling pays off)" "$tmp/auto.err" &&
    cmp -s "$tmp/a1.csv" "$tmp/c-interp.csv" && pass || fail "auto: a short run was not interpreted: $(grep solver "$tmp/auto.err")"
# 361 rows from 300: compiled and stored, the interpreter's table byte for byte
autorun 300 "$tmp/a2.csv" && [ -s "$tmp/cc.log" ] && grep -q "solver .*compiled (auto: compiled in" "$tmp/auto.err" &&
    cmp -s "$tmp/a2.csv" "$tmp/c-interp.csv" && pass || fail "auto: a long run was not compiled: $(grep solver "$tmp/auto.err")"
# a hundredth of 30 000 (300) rows and the solver cached: loaded, not compiled
autorun 30000 "$tmp/a3.csv" && [ ! -e "$tmp/cc.log" ] && grep -q "solver .*compiled (auto: from the cache" "$tmp/auto.err" &&
    cmp -s "$tmp/a3.csv" "$tmp/c-interp.csv" && pass || fail "auto: the cached solver was not used: $(grep solver "$tmp/auto.err")"
# ... but not below that hundredth (the cache's few milliseconds do not pay)
autorun 100000 "$tmp/a4.csv" && [ ! -e "$tmp/cc.log" ] && grep -q "solver .*interpreted (auto: 361 rows" "$tmp/auto.err" &&
    pass || fail "auto: a very short run loaded the cached solver: $(grep solver "$tmp/auto.err")"
# options the generated code does not follow, --engine interpreted, MECH_JIT_AUTO=off
autorun 300 "$tmp/a5.csv" --outputs B && [ ! -e "$tmp/cc.log" ] &&
    grep -q "solver .*interpreted (auto: the compiled solver does not follow --outputs)" "$tmp/auto.err" &&
    pass || fail "auto: --outputs compiled: $(grep solver "$tmp/auto.err")"
autorun 300 "$tmp/a6.csv" --engine interpreted && [ ! -e "$tmp/cc.log" ] &&
    grep -q "solver .*interpreted (--engine interpreted)" "$tmp/auto.err" && pass || fail "auto: --engine interpreted compiled"
rm -f "$tmp/cc.log"
env MECH_JIT_AUTO=off MECH_JIT_AUTO_ROWS=300 MECH_CACHE_DIR="$adir" TMPDIR=$tmp/jt CC=$tmp/cc-log "$MECH" solve \
    mechanisms/fourbar.yaml -q --stats -o "$tmp/a7.csv" 2>"$tmp/auto.err"
[ ! -e "$tmp/cc.log" ] && grep -q "solver .*interpreted (auto: MECH_JIT_AUTO=off)" "$tmp/auto.err" && pass ||
    fail "auto: MECH_JIT_AUTO=off compiled"
# a compiler that fails: a long run says so and is interpreted; a short one, silent
rm -rf "$adir"
env -u MECH_JIT_AUTO MECH_JIT_AUTO_ROWS=300 MECH_CACHE_DIR="$adir" TMPDIR=$tmp/jt CC=false "$MECH" solve \
    mechanisms/fourbar.yaml -q -o "$tmp/a8.csv" 2>"$tmp/auto.err"
grep -q "mech solve: note: the compiled solver: no C compiler ran ('false' .*the interpreter solves the sweep" "$tmp/auto.err" &&
    cmp -s "$tmp/a8.csv" "$tmp/c-interp.csv" && pass || fail "auto: a failing compiler: $(cat "$tmp/auto.err")"
[ -z "$(ls "$tmp/jt")" ] && pass || fail "auto: files left in TMPDIR: $(ls "$tmp/jt")"

# ---- mech batch chooses as mech solve does, on its worker threads -----------
# three files on three threads: the four-bar, the same four-bar under another
# name and path, the double crank; with MECH_JIT_AUTO_ROWS=50 each is long
# enough to compile, but one structure compiles once (the other file waits
# for the build and loads it from the cache); the tables are the
# interpreter's byte for byte
mkdir -p "$tmp/bj" "$tmp/bj-i" "$tmp/bj-c"
cp mechanisms/fourbar.yaml "$tmp/bj/fourbar-copy.yaml"
bfiles="mechanisms/fourbar.yaml $tmp/bj/fourbar-copy.yaml mechanisms/double-crank.yaml"
rm -rf "$adir"
rm -f "$tmp/cc.log"
"$MECH" batch -q -j 3 --engine interpreted --out-dir "$tmp/bj-i" $bfiles >/dev/null 2>"$tmp/bj.err" ||
    fail "batch --engine interpreted: $(cat "$tmp/bj.err")"
env -u MECH_JIT_AUTO MECH_JIT_AUTO_ROWS=50 MECH_CACHE_DIR="$adir" TMPDIR=$tmp/jt CC=$tmp/cc-log \
    "$MECH" batch -j 3 --out-dir "$tmp/bj-c" $bfiles >"$tmp/bj.out" 2>"$tmp/bj.err"
bstatus=$?
[ "$bstatus" = 0 ] && [ "$(grep -c "solver compiled (auto: " "$tmp/bj.err")" = 3 ] &&
    [ "$(grep -c "solver compiled (auto: from the cache" "$tmp/bj.err")" = 1 ] &&
    [ "$(wc -l <"$tmp/cc.log")" = 2 ] && pass ||
    fail "batch: three files, two structures: exit $bstatus, $(wc -l <"$tmp/cc.log") compiler runs: $(cat "$tmp/bj.err")"
bsame=1
for n in fourbar fourbar-copy double-crank; do
    cmp -s "$tmp/bj-i/$n.csv" "$tmp/bj-c/$n.csv" || bsame=0
done
[ $bsame = 1 ] && pass || fail "batch: the compiled tables differ from the interpreter's"
[ -z "$(ls "$tmp/jt")" ] && pass || fail "batch: files left in TMPDIR: $(ls "$tmp/jt")"
# the default: short runs interpreted, no compiler, no message
rm -f "$tmp/cc.log"
env -u MECH_JIT_AUTO MECH_CACHE_DIR="$adir" TMPDIR=$tmp/jt CC=$tmp/cc-log \
    "$MECH" batch -j 3 $bfiles >/dev/null 2>"$tmp/bj.err" && [ ! -e "$tmp/cc.log" ] &&
    ! grep -q "solver" "$tmp/bj.err" && pass || fail "batch: short runs compiled: $(cat "$tmp/bj.err")"
# --engine compiled with a compiler that fails: each file's note, the
# interpreter's tables, exit 0
rm -rf "$adir" "$tmp/bj-c"
env -u MECH_JIT_AUTO MECH_CACHE_DIR="$adir" TMPDIR=$tmp/jt CC=false \
    "$MECH" batch -j 3 --engine compiled --out-dir "$tmp/bj-c" $bfiles >/dev/null 2>"$tmp/bj.err"
bstatus=$?
[ "$bstatus" = 0 ] &&
    grep -q "^$tmp/bj/fourbar-copy.yaml: note: --jit: no C compiler ran ('false'" "$tmp/bj.err" &&
    [ "$(grep -c "note: --jit: no C compiler ran" "$tmp/bj.err")" = 3 ] &&
    cmp -s "$tmp/bj-i/double-crank.csv" "$tmp/bj-c/double-crank.csv" && pass ||
    fail "batch --engine compiled, no compiler: exit $bstatus: $(cat "$tmp/bj.err")"
"$MECH" batch --engine fast mechanisms/fourbar.yaml >/dev/null 2>"$tmp/bj.err"
[ $? = 2 ] && grep -q "engine.*auto, compiled or interpreted" "$tmp/bj.err" && pass ||
    fail "batch --engine fast: $(cat "$tmp/bj.err")"


# ---- mech sweep: one compiled solver for all the variants ----------------
# sweep_pair LABEL FILE SWEEP-ARGS...: the sweep interpreted and compiled
# (-j 3, a fresh cache, the logging compiler): the same summary CSV and
# the same messages byte for byte (-j 1 for their order), the compiler run
# once, and the solver line saying how many variants it solved
sweep_pair() {
    label=$1 file=$2
    shift 2
    rm -rf "$tmp/swc" "$tmp/cc.log"
    "$MECH" sweep "$file" "$@" -j 1 --engine interpreted -o "$tmp/sw-i.csv" 2>"$tmp/sw-i.all"
    want=$?
    grep -v "^mech sweep: solver" "$tmp/sw-i.all" >"$tmp/sw-i.err"
    env MECH_CACHE_DIR="$tmp/swc" TMPDIR=$tmp/jt CC=$tmp/cc-log "$MECH" sweep "$file" "$@" \
        -j 3 --engine compiled -o "$tmp/sw-c.csv" 2>/dev/null
    got=$?
    env MECH_CACHE_DIR="$tmp/swc" TMPDIR=$tmp/jt CC=$tmp/cc-log "$MECH" sweep "$file" "$@" \
        -j 1 --engine compiled -o "$tmp/sw-c1.csv" 2>"$tmp/sw-c.err"
    if [ "$got" != "$want" ]; then
        fail "sweep $label: compiled exits $got, interpreted $want"
    elif ! cmp -s "$tmp/sw-i.csv" "$tmp/sw-c.csv" || ! cmp -s "$tmp/sw-i.csv" "$tmp/sw-c1.csv"; then
        fail "sweep $label: the compiled summary differs: $(diff "$tmp/sw-i.csv" "$tmp/sw-c.csv" | head -n 3)"
    elif ! grep -v "^mech sweep: solver" "$tmp/sw-c.err" | cmp -s - "$tmp/sw-i.err"; then
        fail "sweep $label: other messages: $(grep -v "^mech sweep: solver" "$tmp/sw-c.err" | diff - "$tmp/sw-i.err" | head -n 3)"
    elif [ "$(wc -l <"$tmp/cc.log")" != 1 ]; then
        fail "sweep $label: $(wc -l <"$tmp/cc.log") compiler runs for two sweeps of one structure"
    else
        pass
    fi
}
sweep_pair "double crank lengths" mechanisms/double-crank.yaml --vary l1=55mm:65mm:5 \
    --metric range:B.x --metric maxabs:A.ax --metric max:P.y
has_line "$tmp/sw-c.err" "^mech sweep: solver compiled (from the cache, .*): 5 variants compiled, 0 interpreted$" \
    "sweep: the second run from the cache"
sweep_pair "conveyor lengths, forces" mechanisms/conveyor.yaml --vary l1=55mm:65mm:3 \
    --list l3b=1128.6mm,1140mm,1154.82mm --forces --metric maxabs:driver.torque --metric range:D.x \
    --metric max:A.y
# three variants of that grid fail (two with a gap, one self-locking): the
# interpreter solves them and says so
has_line "$tmp/sw-c.err" ": 6 variants compiled, 3 interpreted$" "sweep: the failing variants"
has_line "$tmp/sw-c.err" "^360 of 361 rows solved, 1 gap$" "sweep: a gap's message"
grep -q ",self-locking,4,nan,nan,nan$" "$tmp/sw-c.csv" && pass || fail "sweep: no self-locking variant"
sweep_pair "conveyor friction and cargo" mechanisms/conveyor.yaml --list mu=0,0.1,0.3 \
    --list cargo=0kg,80kg --forces --metric maxabs:driver.torque
sweep_pair "offset slider-crank" mechanisms/offset-slider-crank.yaml --vary e=10mm:40mm:5 \
    --vary l=110mm:130mm:2 --metric range:B.x
sweep_pair "spring slider-crank, forces" mechanisms/spring-slider-crank.yaml \
    --vary r=35mm:45mm:3 --forces --metric maxabs:driver.torque
sweep_pair "stirling" mechanisms/stirling.yaml --vary a1=14mm:16mm:3 --forces \
    --metric maxabs:driver.torque
# variants assembled another way than guessed: the assembly's warnings come
# from the compiled rows too (tests/warn/steering.yaml, its arm a parameter)
sed -e 's|^ground:|parameters: {arm: 150 mm}\nground:|' \
    -e 's|KL: \[0, 0\], AL: \[150, 0\]|KL: [0, 0], AL: [arm, 0]|' \
    tests/warn/steering.yaml >"$tmp/steering-arm.yaml"
sweep_pair "steering, far from the guess" "$tmp/steering-arm.yaml" --vary arm=148mm:152mm:3
has_line "$tmp/sw-c.err" ": 3 variants compiled, 0 interpreted$" "sweep: steering compiled"
[ "$(grep -c "warning: link 'knuckle_l' is at 15.0 deg in the first position, far from the guess" \
    "$tmp/sw-c.err")" = 3 ] && pass || fail "sweep: the compiled variants' assembly warnings"
# the guesses are a variant's too: a parameter that only guesses picks the
# assembly (B above or below the line of the pivots)
sed -e 's|^ground:|parameters: {gc: 40 deg}\nground:|' -e 's|^  coupler: 40$|  coupler: gc|' \
    -e 's|^  rocker: 100$|  rocker: 2.5 * gc|' -e '/^branch:/,+1d' mechanisms/fourbar.yaml \
    >"$tmp/fourbar-guess.yaml"
sweep_pair "four-bar, guessed assemblies" "$tmp/fourbar-guess.yaml" --list gc=40deg,-40deg \
    --metric max:B.y
grep -q "^1,-0.698.*,ok,361,-0.0279" "$tmp/sw-c.csv" && pass ||
    fail "sweep: the guess of variant 1 did not assemble B below: $(cat "$tmp/sw-c.csv")"
# auto: compiled when the rows of all the variants pay for it
rm -rf "$tmp/swc" "$tmp/cc.log"
env -u MECH_JIT_AUTO MECH_JIT_AUTO_ROWS=1000 MECH_CACHE_DIR="$tmp/swc" TMPDIR=$tmp/jt \
    CC=$tmp/cc-log "$MECH" sweep mechanisms/offset-slider-crank.yaml --vary e=10mm:40mm:3 \
    -o "$tmp/sw-a.csv" 2>"$tmp/sw-a.err"
has_line "$tmp/sw-a.err" "^mech sweep: solver compiled (auto: compiled in .*): 3 variants compiled, 0 interpreted$" \
    "sweep auto: 3 variants of 361 rows from 1000"
env -u MECH_JIT_AUTO MECH_JIT_AUTO_ROWS=2000 MECH_CACHE_DIR="$tmp/swc2" TMPDIR=$tmp/jt \
    CC=$tmp/cc-log "$MECH" sweep mechanisms/offset-slider-crank.yaml --vary e=10mm:40mm:3 \
    -o "$tmp/sw-a2.csv" 2>"$tmp/sw-a.err"
# (interpreted, the sweep says nothing more than before)
[ "$(wc -l <"$tmp/cc.log")" = 1 ] && cmp -s "$tmp/sw-a.csv" "$tmp/sw-a2.csv" &&
    ! grep -q "solver" "$tmp/sw-a.err" && pass ||
    fail "sweep auto, 1083 rows from 2000: $(wc -l <"$tmp/cc.log") compiler runs, other rows, or: $(cat "$tmp/sw-a.err")"
env MECH_CACHE_DIR="$tmp/swc3" TMPDIR=$tmp/jt CC=false "$MECH" sweep \
    mechanisms/offset-slider-crank.yaml --vary e=10mm:40mm:3 --engine compiled -o "$tmp/sw-f.csv" \
    2>"$tmp/sw-f.err"
[ $? = 0 ] && cmp -s "$tmp/sw-a.csv" "$tmp/sw-f.csv" &&
    grep -q "^mech sweep: note: the compiled solver: no C compiler ran ('false'.*; the interpreter solves the variants$" "$tmp/sw-f.err" &&
    pass || fail "sweep --engine compiled, no compiler: $(cat "$tmp/sw-f.err")"
# the engine changes no result: shards solved by either merge (it is not in
# their manifests' arguments)
for k in 0 1; do
    e=compiled
    [ $k = 1 ] && e=interpreted
    env MECH_CACHE_DIR="$tmp/swc" TMPDIR=$tmp/jt CC=$tmp/cc-log "$MECH" sweep \
        mechanisms/offset-slider-crank.yaml --vary e=10mm:40mm:3 --engine $e --shard $k/2 -q \
        -o "$tmp/shard$k.csv" 2>/dev/null
done
"$MECH" merge -o "$tmp/merged.csv" "$tmp/shard0.csv" "$tmp/shard1.csv" 2>"$tmp/merge.err" &&
    ! grep -q engine "$tmp/shard0.csv" && cmp -s "$tmp/merged.csv" "$tmp/sw-a.csv" && pass ||
    fail "sweep: shards of both engines do not merge to the whole: $(cat "$tmp/merge.err")"
[ -z "$(ls "$tmp/jt")" ] && pass || fail "sweep: files left in TMPDIR: $(ls "$tmp/jt")"

# ---- what the compiled rows do not follow, and the assembly's checks -----
# a drawn file assembled at another driver value than its first row's: the
# interpreter's rows (it follows the drawing), with a note
"$MECH" solve tests/drawn/fourbar.yaml -q --engine interpreted -o "$tmp/dr-i.csv" 2>/dev/null
TMPDIR=$tmp/jt "$MECH" solve tests/drawn/fourbar.yaml -q --engine compiled -o "$tmp/dr-c.csv" \
    2>"$tmp/dr.err"
cmp -s "$tmp/dr-i.csv" "$tmp/dr-c.csv" &&
    grep -q "note: --jit does not follow a drawing's driver value other than the first" "$tmp/dr.err" &&
    pass || fail "drawn file, compiled: other rows, or no note: $(cat "$tmp/dr.err")"
# a suspect assembly: the warning and --strict's refusal, compiled as interpreted
for e in interpreted compiled; do
    TMPDIR=$tmp/jt "$MECH" solve tests/warn/steering.yaml -q --strict --engine $e \
        -o "$tmp/st-$e.csv" 2>"$tmp/st-$e.err"
    echo "exit $?" >>"$tmp/st-$e.err"
done
cmp -s "$tmp/st-interpreted.err" "$tmp/st-compiled.err" &&
    grep -q "steering.yaml:39:11: error: link 'knuckle_l' is at 15.0 deg in the first position" "$tmp/st-compiled.err" &&
    grep -q "^exit 1$" "$tmp/st-compiled.err" && [ ! -e "$tmp/st-compiled.csv" ] && pass ||
    fail "steering --strict compiled: $(diff "$tmp/st-interpreted.err" "$tmp/st-compiled.err" | head -n 4)"

summary
