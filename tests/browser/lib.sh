# tests/browser/lib.sh: what the browser tests (run.sh, report.sh) share,
# sourced from the repository root after MECH, OUT and CHROMIUM are set:
# the tools checked, $OUT emptied and made absolute, fail (counts into
# $fails), and browse, headless chromium with no network.
fails=0
for tool in "$CHROMIUM" xmllint python3; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        echo "tests/browser: '$tool' not found"
        echo "  (Debian: apt-get install chromium libxml2-utils python3 fonts-dejavu-core)"
        exit 1
    fi
done
rm -rf "$OUT"
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)

fail() {
    echo "FAIL: $*"
    fails=$((fails + 1))
}

# browse URL WIDTH,HEIGHT SCALE ARGS...: headless chromium, no network (no
# proxy, every host unresolvable), its own profile under $OUT
browse() {
    url=$1 size=$2 scale=$3
    shift 3
    timeout 120 "$CHROMIUM" --headless --no-sandbox --disable-gpu --no-proxy-server \
        --host-resolver-rules="MAP * ~NOTFOUND" --no-first-run --disable-extensions \
        --user-data-dir="$OUT/chromium-profile" --hide-scrollbars \
        --force-device-scale-factor="$scale" --window-size="$size" "$@" "$url"
}
