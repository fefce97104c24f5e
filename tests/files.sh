#!/bin/sh
# tests/files.sh: how `mech` writes its output files (docs/cli.md, section
# Files): symbolic links followed, FIFOs and character devices written
# through, anything else refused; an input is never overwritten; temporary
# files exclusive, random and removed on signals; lost standard output is an
# error; batch output names that collide are refused.
# Run from the repository root:  MECH=build/mech sh tests/files.sh
# Everything happens in $tmp; the only devices used are /dev/null and
# /dev/full (and, as root, a null device node made in $tmp). MECH_QUICK=1:
# shorter tables to write and fewer files to kill a batch among.
NAME=files . tests/lib.sh
big=1000000 nkill=1200  # rows of the table a signal interrupts; files of the killed batches
[ -n "$MECH_QUICK" ] && big=250000 nkill=300

fb=mechanisms/fourbar.yaml
sc=mechanisms/slider-crank.yaml
"$MECH" solve $fb -o "$tmp/fb.csv" 2>/dev/null || fail "mech solve $fb: the reference CSV"

# no_temp DIR LABEL: pass when DIR holds no *.tmp* file
no_temp() {
    if ls -a "$1" | grep -q '\.tmp'; then
        fail "$2: temporary file left: $(ls -a "$1" | grep '\.tmp' | head -n 3)"
    else
        pass
    fi
}

# ---- 1. symbolic links, FIFOs, devices, other kinds ---------------------

d=$tmp/link
mkdir "$d" "$d/real"
echo old >"$d/real/target.csv"
ln -s real/target.csv "$d/link.csv"
if run "solve -o symlink" 0 "$MECH" solve $fb -o "$d/link.csv"; then
    [ -L "$d/link.csv" ] && pass || fail "solve -o symlink: the link was replaced"
    cmp -s "$d/real/target.csv" "$tmp/fb.csv" && pass || fail "solve -o symlink: the target was not written"
    no_temp "$d" "solve -o symlink (link's directory)"
    no_temp "$d/real" "solve -o symlink (target's directory)"
fi

ln -s real/anim.svg "$d/anim.svg"
echo old >"$d/real/anim.svg"
if run "animate -o symlink" 0 "$MECH" animate $fb --frames 10 -o "$d/anim.svg"; then
    [ -L "$d/anim.svg" ] && pass || fail "animate -o symlink: the link was replaced"
    has_line "$d/real/anim.svg" '<svg' "animate -o symlink: the target"
fi

ln -s real/sweep.csv "$d/sweep.csv"
echo old >"$d/real/sweep.csv"
if run "sweep -o symlink" 0 "$MECH" sweep $sc --list l=140mm -o "$d/sweep.csv"; then
    [ -L "$d/sweep.csv" ] && pass || fail "sweep -o symlink: the link was replaced"
    has_line "$d/real/sweep.csv" '^variant \[-\],l \[m\],status' "sweep -o symlink: the target"
fi

mkdir "$d/out"
ln -s ../real/fourbar-points-position.svg "$d/out/fourbar-points-position.svg"
echo old >"$d/real/fourbar-points-position.svg"
if run "plot --out, a figure a symlink" 0 "$MECH" plot $fb --out "$d/out"; then
    [ -L "$d/out/fourbar-points-position.svg" ] && pass || fail "plot: the figure's link was replaced"
    has_line "$d/real/fourbar-points-position.svg" '<svg' "plot: the link's target"
fi

mkdir "$d/bout"
ln -s ../real/fourbar.csv "$d/bout/fourbar.csv"
echo old >"$d/real/fourbar.csv"
if run "batch --out-dir, the CSV a symlink" 0 "$MECH" batch -q $fb --out-dir "$d/bout"; then
    [ -L "$d/bout/fourbar.csv" ] && pass || fail "batch --out-dir: the CSV's link was replaced"
    cmp -s "$d/real/fourbar.csv" "$tmp/fb.csv" && pass || fail "batch --out-dir: the link's target"
fi

ln -s real/missing.csv "$d/dangling.csv"
if run "solve -o a dangling symlink" 3 "$MECH" solve $fb -o "$d/dangling.csv"; then
    has_line "$tmp/err" 'dangling.csv: error: .*does not exist' "solve -o dangling symlink: message"
    [ -L "$d/dangling.csv" ] && pass || fail "solve -o dangling symlink: the link was replaced"
fi

# a FIFO: written through to the reader, still a FIFO afterwards
f=$tmp/fifo
mkfifo "$f"
cat "$f" >"$tmp/from-fifo" &
reader=$!
if run "solve -o FIFO" 0 timeout 60 "$MECH" solve $fb -o "$f"; then
    [ -p "$f" ] && pass || fail "solve -o FIFO: the FIFO was replaced"
fi
[ -p "$f" ] || kill "$reader" 2>/dev/null  # (before the fix the reader waits forever)
wait "$reader" 2>/dev/null
cmp -s "$tmp/from-fifo" "$tmp/fb.csv" && pass || fail "solve -o FIFO: the reader did not get the CSV"

# a character device: a null device node of our own when we may make one
# (root), else /dev/null itself (which only root could replace)
null=$tmp/null
mknod "$null" c 1 3 2>/dev/null || null=/dev/null
if run "solve -o $null" 0 "$MECH" solve $fb -o "$null"; then
    [ -c "$null" ] && pass || fail "solve -o $null: no longer a character device"
fi
[ -c /dev/null ] && pass || fail "/dev/null is no longer a character device"
if run "animate -o $null" 0 "$MECH" animate $fb --frames 10 -o "$null"; then
    [ -c "$null" ] && pass || fail "animate -o $null: no longer a character device"
fi
if run "sweep -o $null" 0 "$MECH" sweep $sc --list l=140mm -o "$null"; then
    [ -c "$null" ] && pass || fail "sweep -o $null: no longer a character device"
    [ ! -e "$null.partial" ] && pass || fail "sweep -o $null: made $null.partial"
fi

# a directory is refused, exit 3, with a message
mkdir "$tmp/adir"
if run "solve -o DIRECTORY" 3 "$MECH" solve $fb -o "$tmp/adir"; then
    has_line "$tmp/err" 'adir: error: cannot write the output: a directory' "solve -o DIRECTORY: message"
    [ -d "$tmp/adir" ] && pass || fail "solve -o DIRECTORY: no longer a directory"
fi
if run "sweep -o DIRECTORY" 3 "$MECH" sweep $sc --list l=140mm -o "$tmp/adir"; then
    has_line "$tmp/err" 'a directory' "sweep -o DIRECTORY: message"
    [ ! -e "$tmp/adir.partial" ] && pass || fail "sweep -o DIRECTORY: left adir.partial"
fi
run "sweep --resume -o DIRECTORY" 2 "$MECH" sweep $sc --list l=140mm --resume -o "$tmp/adir" && pass

# sweep -o OUT: OUT.partial is never a link followed (planted, it is refused)
ln -s victim "$d/p.csv.partial"
echo victim >"$d/victim"
run "sweep, OUT.partial a planted link" 2 "$MECH" sweep $sc --list l=140mm -o "$d/p.csv" && pass
run "sweep --resume, OUT.partial a planted link" 3 "$MECH" sweep $sc --list l=140mm --resume -o "$d/p.csv" && pass
[ "$(cat "$d/victim")" = victim ] && pass || fail "sweep: the target of a planted OUT.partial link was written"

# a socket, when python3 can make one
if command -v python3 >/dev/null 2>&1 &&
        python3 -c 'import socket,sys; socket.socket(socket.AF_UNIX).bind(sys.argv[1])' "$tmp/sock" 2>/dev/null; then
    if run "solve -o SOCKET" 3 "$MECH" solve $fb -o "$tmp/sock"; then
        has_line "$tmp/err" 'a socket' "solve -o SOCKET: message"
        [ -S "$tmp/sock" ] && pass || fail "solve -o SOCKET: no longer a socket"
    fi
fi

# ---- 2. an output that is an input: exit 2, the input untouched ---------

d=$tmp/same
mkdir "$d"
cp $fb "$d/m.yaml"
cp $fb "$d/orig.yaml"
ln "$d/m.yaml" "$d/hard.csv"
ln -s m.yaml "$d/soft.csv"
for out in m.yaml hard.csv soft.csv; do
    if run "solve m.yaml -o $out" 2 "$MECH" solve "$d/m.yaml" -o "$d/$out"; then
        has_line "$tmp/err" "is the input file" "solve m.yaml -o $out: message"
    fi
    cmp -s "$d/m.yaml" "$d/orig.yaml" && pass || fail "solve m.yaml -o $out: the input was changed"
done
run "animate m.yaml -o m.yaml" 2 "$MECH" animate "$d/m.yaml" -o "$d/m.yaml" && pass
cmp -s "$d/m.yaml" "$d/orig.yaml" && pass || fail "animate -o the input: the input was changed"
cp $sc "$d/s.yaml"
cp $sc "$d/s-orig.yaml"
run "sweep s.yaml -o s.yaml" 2 "$MECH" sweep "$d/s.yaml" --list l=140mm -o "$d/s.yaml" && pass
cmp -s "$d/s.yaml" "$d/s-orig.yaml" && pass || fail "sweep -o the input: the input was changed"
mkdir "$d/figs"
ln -s ../m.yaml "$d/figs/m-points-position.svg"
run "plot, a figure that is the input" 2 "$MECH" plot "$d/m.yaml" --out "$d/figs" && pass
cmp -s "$d/m.yaml" "$d/orig.yaml" && pass || fail "plot over the input: the input was changed"
ls "$d/figs" | grep -q velocity && fail "plot over the input: figures were written" || pass
# batch: DIR/NAME.csv is a mechanism file, or a golden file
ln "$d/m.yaml" "$d/m.csv"
if run "batch --out-dir, the CSV an input" 2 "$MECH" batch -q "$d/m.yaml" --out-dir "$d"; then
    has_line "$tmp/err" "m.csv is the input file" "batch --out-dir over an input: message"
fi
cmp -s "$d/m.yaml" "$d/orig.yaml" && pass || fail "batch --out-dir over an input: the input was changed"
mkdir "$d/golden"
cp tests/golden/fourbar.csv "$d/golden/fourbar.csv"
if run "batch --out-dir = --golden" 2 "$MECH" batch -q $fb --out-dir "$d/golden" --golden "$d/golden"; then
    has_line "$tmp/err" "golden/fourbar.csv is the input file" "batch --out-dir = --golden: message"
fi
cmp -s "$d/golden/fourbar.csv" tests/golden/fourbar.csv && pass ||
    fail "batch --out-dir = --golden: the golden file was changed"

# ---- 3. temporary files: exclusive, unpredictable, in the target's directory

# sweep: a symbolic link planted at the old predictable name OUT.tmpPID
d=$tmp/plant
mkdir "$d"
echo victim >"$d/victim"
if sh -c 'ln -s victim "$1.tmp$$" && exec "$2" sweep "$3" --list l=140mm -o "$1"' sh \
        "$d/out.csv" "$MECH" $sc >"$tmp/out" 2>"$tmp/err"; then
    pass
else
    fail "sweep with a planted link: exit status $? ($(head -n 1 "$tmp/err"))"
fi
[ "$(cat "$d/victim")" = victim ] && pass || fail "sweep -o: the planted link's target was overwritten"
has_line "$d/out.csv" '^variant \[-\],l \[m\],status' "sweep -o with a planted link: the output"

# batch --golden: no temporary file at all (it was mech-batch-PID-I.csv in TMPDIR)
mkdir "$d/tmpdir"
if TMPDIR=$d/tmpdir sh -c 'ln -s ../victim "$TMPDIR/mech-batch-$$-0.csv" && exec "$1" batch -q "$2" --golden tests/golden' \
        sh "$MECH" $fb >"$tmp/out" 2>"$tmp/err"; then
    pass
else
    fail "batch --golden: exit status $? ($(head -n 1 "$tmp/err"))"
fi
has_line "$tmp/out" 'fourbar .* match' "batch --golden: matches"
[ "$(ls "$d/tmpdir" | wc -l)" -eq 1 ] && [ -L "$d/tmpdir/mech-batch-"*"-0.csv" ] && pass ||
    fail "batch --golden used the temporary directory: $(ls -l "$d/tmpdir")"
[ "$(cat "$d/victim")" = victim ] && pass || fail "batch --golden: the planted link's target was overwritten"

# the final file's mode is 0666 less the umask, as a plain fopen would make it
for mask in 022 077 002; do
    rm -f "$d/mode.csv"
    (umask $mask && "$MECH" solve $fb --level positions -o "$d/mode.csv") 2>/dev/null
    want=$(printf '%o' $((0666 & ~0$mask)))
    got=$(stat -c %a "$d/mode.csv" 2>/dev/null)
    [ "$got" = "$want" ] && pass || fail "umask $mask: output mode $got, expected $want"
done

# ---- 4. a signal during the write removes the temporary file ------------

# A 10^6-row CSV takes long enough to write that the polling loop sees its
# temporary file; then the signal. Background jobs of a non-interactive
# shell ignore SIGINT: tests/sigexec.c restores its default action before
# starting mech, and without it the ignored SIGINT must stay ignored (as
# under nohup): mech finishes and writes its file.
# catch SIG DIR [LAUNCHER...]: start mech writing DIR/big.csv, send SIG as
# soon as DIR/big.csv.tmp* exists; $seen 1 when it did, $status mech's exit.
catch() {
    sig=$1 dir=$2
    shift 2
    mkdir "$dir"
    "$@" "$MECH" solve $fb --steps $big --outputs B --level positions -o "$dir/big.csv" 2>/dev/null &
    pid=$!
    seen=0 i=0
    while [ $i -lt 3000 ] && kill -0 $pid 2>/dev/null; do
        if ls "$dir" | grep -q '\.tmp'; then
            seen=1
            kill -$sig $pid
            break
        fi
        sleep 0.01
        i=$((i + 1))
    done
    { wait $pid; } 2>/dev/null
    status=$?
}
for sig in TERM HUP INT; do
    if [ $sig = INT ]; then catch $sig "$tmp/sig$sig" "$SIGEXEC" default; else catch $sig "$tmp/sig$sig"; fi
    if [ $seen -eq 1 ]; then
        [ $status -gt 128 ] && pass || fail "SIG$sig during the write: exit status $status, expected death by the signal"
        no_temp "$tmp/sig$sig" "SIG$sig during the write"
        [ -e "$tmp/sig$sig/big.csv" ] && fail "SIG$sig during the write: the output appeared" || pass
    else
        fail "SIG$sig: the temporary file was never seen (the write was too fast?)"
    fi
done
catch INT "$tmp/sigign"
if [ $seen -eq 1 ]; then
    [ $status -eq 0 ] && pass || fail "an ignored SIGINT during the write: exit status $status, expected 0"
    [ "$(wc -l <"$tmp/sigign/big.csv")" -eq $((big + 2)) ] && pass || fail "an ignored SIGINT: the output is not whole"
    no_temp "$tmp/sigign" "an ignored SIGINT"
fi

# ---- 5. lost standard output: exit 3 with a message ---------------------

if [ -w /dev/full ]; then
    for cmd in "check $fb" "equations $fb" "batch -q $fb" "compare tests/golden/fourbar.csv tests/golden/fourbar.csv" \
               "sweep $sc --list l=140mm" "solve $fb -o -" "solve $fb" "animate $fb --frames 10" "--help" "check --help"; do
        # shellcheck disable=SC2086
        "$MECH" $cmd >/dev/full 2>"$tmp/err"
        status=$?
        [ $status -eq 3 ] && pass || fail "mech $cmd >/dev/full: exit status $status, expected 3"
        if grep -q 'cannot write standard output: No space left on device' "$tmp/err"; then pass; else
            fail "mech $cmd >/dev/full: no message ($(head -n 1 "$tmp/err"))"
        fi
        [ "$(grep -c 'cannot write standard output' "$tmp/err")" -eq 1 ] && pass ||
            fail "mech $cmd >/dev/full: the message is not printed exactly once"
    done
fi

# ---- 6. batch: colliding output names; --out-dir created ----------------

d=$tmp/collide
mkdir "$d" "$d/a" "$d/b"
cp $fb "$d/a/m.yaml"
cp $sc "$d/b/m.yaml"
if run "batch, two files named m.yaml" 2 "$MECH" batch -q "$d/a/m.yaml" "$d/b/m.yaml" --out-dir "$d/out"; then
    has_line "$tmp/err" "a/m.yaml and .*b/m.yaml would both be written to .*out/m.csv" "batch collision: message"
    [ -e "$d/out" ] && fail "batch collision: the output directory was made" || pass
    [ -s "$tmp/out" ] && fail "batch collision: a table was printed (something was solved)" || pass
fi
if run "batch --shard, two files named m.yaml in two shards" 2 "$MECH" batch -q --shard 0/2 "$d/a/m.yaml" "$d/b/m.yaml" --out-dir "$d/out"; then
    has_line "$tmp/err" "would both be written to" "batch --shard collision: message"
fi
run "batch, the same names without --out-dir" 0 "$MECH" batch -q "$d/a/m.yaml" "$d/b/m.yaml" && pass
if run "batch --out-dir missing/deep" 0 "$MECH" batch -q $fb $sc --out-dir "$d/new/deep/er"; then
    [ -f "$d/new/deep/er/fourbar.csv" ] && [ -f "$d/new/deep/er/slider-crank.csv" ] && pass ||
        fail "batch --out-dir missing/deep: the CSVs are not there"
fi
echo file >"$d/plain"
if run "batch --out-dir a file" 3 "$MECH" batch -q $fb --out-dir "$d/plain"; then
    has_line "$tmp/err" 'cannot create the directory' "batch --out-dir a file: message"
fi

# ---- 12. whole numbers from the command line: NaN and huge refused ------

for v in nan -nan inf 1e30 -1e30 1e300; do
    run "solve --steps $v" 2 "$MECH" solve $fb --steps "$v" && pass
    run "solve --max-iter $v" 2 "$MECH" solve $fb --max-iter "$v" && pass
    run "plot --steps $v" 2 "$MECH" plot $fb --steps "$v" --out "$tmp/never" && pass
    run "animate --frames $v" 2 "$MECH" animate $fb --frames "$v" && pass
    run "animate --frame $v" 2 "$MECH" animate $fb --frame "$v" && pass
done
[ -e "$tmp/never" ] && fail "plot --steps with a bad value made its directory" || pass

# messages from worker threads (strerror_r): every missing file named with its reason
set --
for i in 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16; do set -- "$@" "$tmp/missing$i.yaml"; done
if run "batch -j 8 of 16 missing files" 3 "$MECH" batch -j 8 "$@"; then
    n=$(grep -c 'missing[0-9]*.yaml: error: cannot open: No such file or directory' "$tmp/err")
    [ "$n" -eq 16 ] && pass || fail "batch of missing files: $n of 16 messages name the reason"
fi

# a batch killed by SIGTERM while its workers create CSVs leaves no temporary
# file behind: creating and registering a temporary file is one step the
# signal handler waits for (src/output/output.c). Before, 26 files in 15 kills.
d=$tmp/killed
mkdir -p "$d/in"
i=0
while [ $i -lt $nkill ]; do i=$((i + 1)); cp mechanisms/fourbar.yaml "$d/in/f$i.yaml"; done
left=0
for delay in 0.2 0.3 0.4 0.25 0.35 0.45; do
    rm -rf "$d/out" && mkdir "$d/out"
    "$MECH" batch -q -j 2 --out-dir "$d/out" "$d/in"/*.yaml >/dev/null 2>&1 &
    pid=$!
    sleep $delay
    kill -TERM $pid 2>/dev/null
    wait $pid 2>/dev/null
    left=$((left + $(ls "$d/out" | grep -c '\.tmp')))
done
[ "$left" -eq 0 ] && pass || fail "killed batches left $left temporary files in their out-dirs"
rm -rf "$d"

summary
