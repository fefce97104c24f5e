#!/bin/sh
# tests/watch.sh: `mech watch` on the command line, with a small client
# (tests/watch_client.py, python3's standard library; the browser's view is
# tests/browser/watch.sh): usage errors, the address on the first line of
# standard output, listening on 127.0.0.1 only (/proc/net/tcp and tcp6),
# the page and the state (rows and points equal `mech solve`'s), requests
# refused (Host, method, paths, sizes), a long poll ended by a save (a
# temporary file renamed over the watched one) within 2 s, a broken file's
# error FILE:LINE:COLUMN with the last good drawing kept, a port already
# taken, --set (the state is mech solve --set's), and SIGINT and SIGTERM:
# exit status 0, the port closed.
# Run from the repository root:  MECH=build/mech sh tests/watch.sh
NAME=watch
. tests/lib.sh

four=mechanisms/fourbar.yaml
CLIENT="python3 tests/watch_client.py"

# ---- usage: status 2 (3 for a file that cannot be read), a precise message
run "help" 0 "$MECH" watch --help && has_line "$tmp/out" "usage: mech watch FILE" "help"
run "mech help watch" 0 "$MECH" help watch && has_line "$tmp/out" "127.0.0.1" "help watch"
run "in the list" 0 "$MECH" --help && has_line "$tmp/out" "^  watch " "mech --help"
run "no file" 2 "$MECH" watch && has_line "$tmp/err" "no file given" "no file"
run "two files" 2 "$MECH" watch $four $four && has_line "$tmp/err" "one file at a time" "two files"
run "unknown option" 2 "$MECH" watch $four --bogus && has_line "$tmp/err" "unknown option '--bogus'" "--bogus"
run "--port x" 2 "$MECH" watch $four --port x && has_line "$tmp/err" "--port needs a port number" "--port x"
run "--port 70000" 2 "$MECH" watch $four --port 70000 && has_line "$tmp/err" "--port needs" "--port 70000"
run "--port alone" 2 "$MECH" watch $four --port && has_line "$tmp/err" "option '--port' needs a value" "--port"
run "--frames 1" 2 "$MECH" watch $four --frames 1 && has_line "$tmp/err" "--frames needs" "--frames 1"
run "--set bad" 2 "$MECH" watch $four --set r && has_line "$tmp/err" "--set needs NAME=VALUE" "--set r"
run "missing file" 3 "$MECH" watch "$tmp/none.yaml" && has_line "$tmp/err" "none.yaml: error: cannot read" "missing file"

# start_watch FILE LOG ARGS...: mech watch in the background ($wpid); its
# address in $url, its port in $port (empty after 10 s without it)
start_watch() {
    file=$1 log=$2
    shift 2
    "$MECH" watch "$file" "$@" >"$log.out" 2>"$log.err" &
    wpid=$!
    i=0
    while [ ! -s "$log.out" ] && [ $i -lt 100 ] && kill -0 $wpid 2>/dev/null; do
        sleep 0.1
        i=$((i + 1))
    done
    url=$(head -n 1 "$log.out")
    port=$(echo "$url" | sed -n 's|^http://127\.0\.0\.1:\([0-9][0-9]*\)/$|\1|p')
}

# stop_watch SIGNAL LOG: the signal, then exit status 0, "stopped", the port closed
stop_watch() {
    kill -"$1" $wpid
    wait $wpid
    st=$?
    [ $st -eq 0 ] && pass || fail "mech watch exited $st on SIG$1, not 0 ($(tail -n 2 "$2.err"))"
    has_line "$2.err" "^mech watch: stopped" "SIG$1"
    $CLIENT closed "$port" >"$tmp/closed.txt" || fail "the port is still open after SIG$1"
}

# listens_on_loopback_only PORT: a LISTEN entry (state 0A) on 127.0.0.1
# (0100007F) in /proc/net/tcp, none on another address, none in tcp6
listens_on_loopback_only() {
    hex=$(printf '%04X' "$1")
    lines=$(awk -v p=":$hex" '$4 == "0A" && substr($2, length($2) - 4) == p { print $2 }' \
        /proc/net/tcp /proc/net/tcp6 2>/dev/null)
    if [ "$lines" = "0100007F:$hex" ]; then
        pass
    else
        fail "port $1 listens on '$(echo $lines)', not on 127.0.0.1 (0100007F:$hex) alone"
    fi
}

# ---- versions of the watched file, and what mech solve says of them
cp $four "$tmp/v1.yaml"
sed 's/^      A: \[20, 0\]$/      A: [25, 0]/' $four >"$tmp/v2.yaml"
sed 's/^      B: \[60, 0\]$/      B: [60, 0/' $four >"$tmp/broken.yaml"
cmp -s "$tmp/v1.yaml" "$tmp/v2.yaml" && fail "v2.yaml is v1.yaml (the edit did not apply)"
cmp -s "$tmp/v1.yaml" "$tmp/broken.yaml" && fail "broken.yaml is v1.yaml (the edit did not apply)"
for v in v1 v2; do
    "$MECH" solve "$tmp/$v.yaml" -o "$tmp/solve-$v.csv" || fail "mech solve $v.yaml"
    "$MECH" solve "$tmp/$v.yaml" --outputs O,A,B,C,P --level positions \
        -o "$tmp/positions-$v.csv" || fail "mech solve $v.yaml --outputs O,A,B,C,P"
done

# ---- serving while the file changes; then SIGINT
cp "$tmp/v1.yaml" "$tmp/w.yaml"
start_watch "$tmp/w.yaml" "$tmp/w1"
if [ -n "$port" ]; then
    pass
    listens_on_loopback_only "$port"
    run "a port already taken" 3 "$MECH" watch $four --port "$port" &&
        has_line "$tmp/err" "cannot listen on 127.0.0.1:$port: Address already in use" "port taken"
    $CLIENT serve "$url" "$tmp/w.yaml" "$tmp" >"$tmp/client.txt"
    st=$?
    grep -v '\[ok\]$' "$tmp/client.txt"
    [ $st -eq 0 ] && pass || fail "tests/watch_client.py serve ($(grep -c '\[ok\]$' "$tmp/client.txt") checks passed)"
    has_line "$tmp/w1.err" "^mech watch: version 3: not solved" "the terminal says version 3 failed"
    stop_watch INT "$tmp/w1"
else
    fail "mech watch printed '$url' first, not http://127.0.0.1:PORT/ ($(cat "$tmp/w1.err"))"
    kill $wpid 2>/dev/null
fi

# ---- --set: the page is the solve of the file with the parameter replaced
sc=mechanisms/slider-crank.yaml
"$MECH" solve $sc --set l=150mm -o "$tmp/solve-set.csv" || fail "mech solve --set l=150mm"
"$MECH" solve $sc --set l=150mm --outputs O,A,B --level positions -o "$tmp/positions-set.csv" ||
    fail "mech solve --set l=150mm --outputs O,A,B"
cp $sc "$tmp/s.yaml"
start_watch "$tmp/s.yaml" "$tmp/w3" --set l=150mm --set r=40mm
if [ -n "$port" ]; then
    $CLIENT state "$url" "$tmp" set >"$tmp/set.txt"
    st=$?
    grep -v '\[ok\]$' "$tmp/set.txt"
    [ $st -eq 0 ] && pass || fail "mech watch --set: the state is not mech solve --set's"
    stop_watch INT "$tmp/w3"
else
    fail "mech watch --set printed no address ($(cat "$tmp/w3.err"))"
    kill $wpid 2>/dev/null
fi

# ---- SIGTERM, on a port asked for; a file broken from the start
cp "$tmp/broken.yaml" "$tmp/b.yaml"
start_watch "$tmp/b.yaml" "$tmp/w2" --port 0
if [ -n "$port" ]; then
    python3 - "$url" "$tmp/b.yaml" >"$tmp/b.txt" <<'EOF' || fail "a file broken from the start: $(cat "$tmp/b.txt")"
import json, re, sys, urllib.request
s = json.load(urllib.request.urlopen(sys.argv[1] + "state", timeout=10))
ok = s["version"] == 1 and s["good"] == 0 and s["html"] == "" and \
    re.search("^" + re.escape(sys.argv[2]) + r":\d+:\d+: error: ", s["error"], re.M)
print(s["error"])
sys.exit(0 if ok else 1)
EOF
    stop_watch TERM "$tmp/w2"
else
    fail "mech watch (broken file) printed no address ($(cat "$tmp/w2.err"))"
    kill $wpid 2>/dev/null
fi

summary
