#!/bin/sh
# tests/valgrind.sh: `mech solve` (with forces) on every mechanism, the
# failure cases and the other commands (simulate and fit among them) (mech watch served, edited and
# stopped by SIGINT) under valgrind: no invalid reads or writes, no leaks.
# Run from the repository root:  MECH=build/mech sh tests/valgrind.sh
MECH=${MECH:-build/mech}
command -v valgrind >/dev/null || { echo "valgrind: not installed (apt-get install valgrind)" >&2; exit 2; }
tmp=${TMPDIR:-/tmp}/mech-valgrind.$$
mkdir "$tmp" || exit 2
trap 'rm -rf "$tmp"' EXIT
passed=0
failed=0
check() {  # check LABEL ARGS...: valgrind must report nothing (exit 99 on errors)
    label=$1
    shift
    valgrind -q --leak-check=full --show-leak-kinds=definite,indirect \
        --errors-for-leak-kinds=definite,indirect --error-exitcode=99 \
        --suppressions=tests/valgrind.supp \
        "$MECH" "$@" >"$tmp/out" 2>"$tmp/err"
    if [ $? -eq 99 ]; then
        failed=$((failed + 1))
        echo "FAIL: $label"
        sed 's/^/    /' "$tmp/err" | head -n 30
    else
        passed=$((passed + 1))
    fi
}
for f in mechanisms/*.yaml tests/solve/*.yaml tests/hard/*.yaml; do
    check "mech solve --forces $f" solve "$f" --forces --friction both -o "$tmp/x.csv"
done
for f in mechanisms/*.yaml tests/hard/redundant-parallelogram.yaml; do
    check "mech codegen $f" codegen "$f" -o "$tmp/gen.c" --header "$tmp/gen.h"
done
check "mech batch" batch -j 2 -q mechanisms/*.yaml tests/solve/*.yaml
check "mech sweep" sweep mechanisms/slider-crank.yaml --list l=45mm,140mm --metric range:x_B.s -j 2
check "mech equations (named parameters)" equations mechanisms/conveyor.yaml
check "mech equations --format latex" equations --format latex mechanisms/stirling.yaml
check "mech solve --sensitivity" solve mechanisms/conveyor.yaml --sensitivity l1,xF --steps 36 -q -o "$tmp/s.csv"
sed 's/^  r: 40 mm .*/  r: {value: 40 mm, tolerance: 0.05 mm}/' mechanisms/offset-slider-crank.yaml >"$tmp/tol.yaml"
check "mech solve --tolerances" solve "$tmp/tol.yaml" --tolerances --sensitivity e -q -o "$tmp/t.csv"
check "mech solve --sensitivity, unknown name" solve mechanisms/conveyor.yaml --sensitivity zz -q
# the compiled solvers (a private cache): one solve, one sweep of variants
MECH_CACHE_DIR=$tmp/cache check "mech solve --engine compiled" solve mechanisms/conveyor.yaml \
    --forces --engine compiled -o "$tmp/x.csv"
MECH_CACHE_DIR=$tmp/cache check "mech sweep --engine compiled" sweep mechanisms/conveyor.yaml \
    --list l1=58mm,60mm,62mm --forces --metric maxabs:driver.torque --engine compiled -j 2
check "mech sweep flywheel" sweep mechanisms/spring-slider-crank.yaml --list r=30mm,40mm --forces --metric flywheel:0.02 -j 2
check "mech solve --speed-fluctuation" solve mechanisms/spring-slider-crank.yaml --stats --speed-fluctuation 0.02 -o "$tmp/x.csv"
check "mech check bad springs" check tests/bad/63-springs.yaml
check "mech plot" plot mechanisms/fourbar.yaml --out "$tmp/plots"
check "mech animate" animate mechanisms/fourbar.yaml -o "$tmp/a.svg"
check "mech report --forces" report mechanisms/fourbar.yaml --forces -o "$tmp/r.html"
check "mech report, a partial sweep" report tests/hard/non-grashof-crank.yaml -o "$tmp/p.html"
check "mech draw (a guessed pose)" draw mechanisms/fourbar.yaml --frame 30 -o "$tmp/d.svg"
check "mech check --draw" check mechanisms/offset-slider-crank.yaml --draw "$tmp/d.svg"
check "mech draw, no assembly" draw tests/hard/non-grashof-crank.yaml --at 180 -o "$tmp/d.svg"
check "mech solve -o OUT.h5 (HDF5)" solve mechanisms/fourbar.yaml --forces -o "$tmp/run.h5"
check "mech compare an HDF5 file" compare "$tmp/run.h5" tests/golden/fourbar.csv --columns A.x
check "mech solve, a rise-dwell-return program" solve tests/programs/follower.yaml -o "$tmp/prog.csv"
check "mech solve, laws of exp, log, tanh" solve tests/programs/functions.yaml -o "$tmp/prog.csv"
check "mech solve, a cam driving a four-bar" solve mechanisms/cams/cam-fourbar.yaml -o "$tmp/cam.csv"
check "mech cam, the profile and outlines" cam mechanisms/cams/translating-roller.yaml -o "$tmp/p.csv" --svg "$tmp/p.svg" --dxf "$tmp/p.dxf"
check "mech solve --forces, a cam held by a spring" solve tests/cams/forces-fourbar.yaml -o "$tmp/camf.csv"
check "mech animate, a cam turning" animate mechanisms/cams/translating-roller.yaml -o "$tmp/cam.svg"
check "mech solve --forces, a cam given by points (GSL's splines)" solve tests/cams/points.yaml --forces -o "$tmp/pts.csv"
check "mech simulate (BDF)" simulate tests/dynamics/pendulum.yaml --to 1 --step 0.05 -o "$tmp/sim.csv"
check "mech simulate (two free cranks, Adams)" simulate mechanisms/dynamics/five-bar-free.yaml --to 0.5 --method adams -o "$tmp/sim.csv"
check "mech simulate --stop-at-rest" simulate tests/dynamics/pendulum.yaml --stop-at-rest -o "$tmp/sim.csv"
"$MECH" solve tests/fit/fourbar.yaml --from 0 --to 330 --steps 11 --outputs P --level positions \
    --units file -o "$tmp/all.csv" && cut -d, -f1-3 "$tmp/all.csv" >"$tmp/path.csv"
sed -e 's/^  r: 20 mm/  r: 22 mm/' -e 's/^  l: 60 mm/  l: 55 mm/' tests/fit/fourbar.yaml >"$tmp/moved.yaml"
check "mech fit (4 starts on 2 threads)" fit "$tmp/moved.yaml" --free r=15:25,l=50:70 --target "$tmp/path.csv" \
    --starts 4 -j 2 -o "$tmp/best.yaml"
check "mech fit, unknown column" fit "$tmp/moved.yaml" --free r --target "$tmp/all.csv" --column Q.x
# the fit: section's constraints steering a free-timing fit (both active)
cp "$tmp/moved.yaml" "$tmp/cons.yaml"
printf 'fit:\n  constraints: ["l / r >= 3.1"]\n  transmission: {links: [coupler, rocker], min: 55 deg}\n' >>"$tmp/cons.yaml"
check "mech fit, constraints and free timing" fit "$tmp/cons.yaml" --free r,l,b --target "$tmp/path.csv" --free-timing

# mech watch: served, saved (good, broken, good again), requests refused,
# a long poll and an idle connection open at SIGINT; nothing may leak
cp mechanisms/fourbar.yaml "$tmp/w.yaml"
valgrind -q --suppressions=tests/valgrind.supp --leak-check=full --show-leak-kinds=definite,indirect \
    --errors-for-leak-kinds=definite,indirect --error-exitcode=99 \
    "$MECH" watch "$tmp/w.yaml" >"$tmp/url" 2>"$tmp/werr" &
wpid=$!
python3 - "$tmp/url" "$tmp/w.yaml" <<'EOF2'
import json, os, shutil, socket, sys, time, urllib.request
for _ in range(600):  # the address, under valgrind: up to 60 s
    url = open(sys.argv[1]).read().strip()
    if url:
        break
    time.sleep(0.1)
port = int(url.rsplit(":", 1)[1].strip("/"))
def state(since=None):
    q = "" if since is None else f"?since={since}"
    return json.load(urllib.request.urlopen(url + "state" + q, timeout=120))
urllib.request.urlopen(url, timeout=120).read()
v = state()["version"]
for data in (b"GET / HTTP/1.1\r\nHost: evil.example\r\n\r\n", b"POST / HTTP/1.1\r\n\r\n",
             b"GET /x HTTP/1.1\r\nHost: localhost\r\n\r\n" + b"X: y\r\n" * 2000):
    with socket.create_connection(("127.0.0.1", port), timeout=60) as s:
        s.sendall(data)
        s.recv(100)
text = open(sys.argv[2]).read()
for new in (text.replace("A: [20, 0]", "A: [25, 0]"), text.replace("A: [20, 0]", "A: [25, 0"), text):
    with open(sys.argv[2] + ".tmp", "w") as f:
        f.write(new)
    os.replace(sys.argv[2] + ".tmp", sys.argv[2])
    v = state(since=v)["version"]
idle = socket.create_connection(("127.0.0.1", port), timeout=60)
poll = socket.create_connection(("127.0.0.1", port), timeout=60)
poll.sendall(f"GET /state?since={v} HTTP/1.1\r\nHost: localhost\r\n\r\n".encode())
time.sleep(1)
print(v)
EOF2
kill -INT $wpid
wait $wpid
if [ $? -eq 0 ] && grep -q "^mech watch: stopped" "$tmp/werr"; then
    passed=$((passed + 1))
else
    failed=$((failed + 1))
    echo "FAIL: mech watch"
    sed 's/^/    /' "$tmp/werr" | head -n 30
fi
echo "valgrind: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
