#!/bin/sh
# tests/report.sh: `mech report` on the command line (no browser: that is
# tests/browser/report.sh): exit statuses and messages of bad usage and bad
# input, the page written whole and never over the input, and what the page
# holds, against the other commands' own output: it is well-formed XML,
# loads nothing from elsewhere, holds every figure of `mech plot` (by
# title), the text of `mech equations`, the lines of `mech check`, the
# warnings of `mech solve`, and behind its slider the rows of `mech solve`'s
# CSV bit for bit. MECH_QUICK=1: the pages of five cases (of thirteen): the
# four-bar, forces, a warning, a partial sweep, --set.
# Run from the repository root:  MECH=build/mech sh tests/report.sh
NAME=report
. tests/lib.sh

four=mechanisms/fourbar.yaml

# rrun: run, and no sanitizer report on stderr (a leak on a failing exit
# keeps the exit status under LeakSanitizer, so it is looked for here)
rrun() {
    run "$@" || return 1
    if grep -q "Sanitizer\|runtime error:" "$tmp/err"; then
        fail "$1: $(grep -m 1 "Sanitizer\|runtime error:" "$tmp/err")"
        return 1
    fi
    return 0
}

# ---- usage and input errors: status 2 (3 for files), a precise message
rrun "help" 0 "$MECH" report --help && has_line "$tmp/out" "usage: mech report FILE" "help"
rrun "mech help report" 0 "$MECH" help report && has_line "$tmp/out" "--frames N" "help report"
rrun "no file" 2 "$MECH" report && has_line "$tmp/err" "no file given" "no file"
rrun "unknown option" 2 "$MECH" report $four --bogus && has_line "$tmp/err" "unknown option '--bogus'" "unknown option"
rrun "option without value" 2 "$MECH" report $four -o && has_line "$tmp/err" "option '-o' needs a value" "-o"
rrun "two files" 2 "$MECH" report $four $four && has_line "$tmp/err" "one file at a time" "two files"
rrun "--steps 0" 2 "$MECH" report $four --steps 0 && has_line "$tmp/err" "--steps needs a whole number" "--steps 0"
rrun "--frames 1" 2 "$MECH" report $four --frames 1 && has_line "$tmp/err" "--frames needs" "--frames 1"
rrun "--duration 0" 2 "$MECH" report $four --duration 0 && has_line "$tmp/err" "--duration needs" "--duration 0"
rrun "--friction" 2 "$MECH" report $four --friction sometimes && has_line "$tmp/err" "on, off or both" "--friction"
rrun "--from alone" 2 "$MECH" report $four --from 10 && has_line "$tmp/err" "--from and --to go together" "--from"
rrun "--from bad" 2 "$MECH" report $four --from 10kg --to 20 && has_line "$tmp/err" "mech report: --from '10kg'" "--from 10kg"
rrun "--set bad" 2 "$MECH" report $four --set r && has_line "$tmp/err" "--set needs NAME=VALUE" "--set r"
rrun "--set unknown" 2 "$MECH" report mechanisms/slider-crank.yaml --set nosuch=3mm &&
    has_line "$tmp/err" "nosuch" "--set nosuch"
rrun "--outputs unknown" 2 "$MECH" report $four --outputs B,Q && has_line "$tmp/err" "mech report: --outputs:" "--outputs Q"
rrun "missing file" 3 "$MECH" report "$tmp/none.yaml" -o "$tmp/x.html" && has_line "$tmp/err" "none.yaml" "missing file"
printf 'name: x\nlinks:\n  crank: {points: {O: [0, 0], A: [1, 0]}, mas: 1}\n' >"$tmp/bad.yaml"
rrun "invalid file" 2 "$MECH" report "$tmp/bad.yaml" -o "$tmp/x.html" && has_line "$tmp/err" "bad.yaml:[0-9]*:[0-9]*: error" "file:line:col"
[ ! -e "$tmp/x.html" ] && pass || fail "a page was written for invalid input"

# ---- the input is never the output; a failed run leaves the output alone
cp $four "$tmp/four.yaml"
rrun "output = input" 2 "$MECH" report "$tmp/four.yaml" -o "$tmp/four.yaml" &&
    has_line "$tmp/err" "is the input file" "output = input"
cmp -s $four "$tmp/four.yaml" && pass || fail "the input was changed"
ln -s four.yaml "$tmp/link.html"
rrun "output = link to input" 2 "$MECH" report "$tmp/four.yaml" -o "$tmp/link.html"
cmp -s $four "$tmp/four.yaml" && pass || fail "the input was changed through a link"
echo "keep me" >"$tmp/old.html"
rrun "never assembles" 1 "$MECH" report tests/hard/non-grashof-crank.yaml --from 120 --to 240 \
    -o "$tmp/old.html" && has_line "$tmp/err" "0 of the sweep's 361 positions were solved; nothing written" "no row solved"
[ "$(cat "$tmp/old.html")" = "keep me" ] && pass || fail "a failed run replaced the output"
rrun "directory missing" 3 "$MECH" report $four -o "$tmp/no/such/dir/r.html"
rrun "stdout" 0 "$MECH" report $four && has_line "$tmp/out" "^<!DOCTYPE html>" "stdout"

# ---- the page against the other commands
# check_page PAGE CSV FIGDIR EQUATIONS CHECK_OUT SOLVE_ERR: python prints FAIL lines
check_page() {
    python3 - "$@" <<'EOF'
import csv, json, os, re, struct, sys
import xml.dom.minidom
page, csvfile, figdir, eqfile, checkfile, solveerr = sys.argv[1:7]
def esc(s):  # as the page escapes text: & < > " (not ')
    return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")
text = open(page, encoding="utf-8").read()
bad = []
try:
    xml.dom.minidom.parseString(text.encode())
except Exception as e:
    bad.append(f"not well-formed XML: {e}")
# nothing to load: no URL but the XML namespaces, no src=, <link>, @import
urls = set(re.findall(r"(?:https?:)?//[A-Za-z0-9.-]+\.[a-z]{2,}[^\s\"'<>)]*", text))
urls -= {"http://www.w3.org/1999/xhtml", "http://www.w3.org/2000/svg",
         "http://www.w3.org/1999/xlink"}
if urls:
    bad.append(f"references elsewhere: {sorted(urls)[:5]}")
for pat in (r"\ssrc\s*=", r"<link\b", r"@import", r"url\((?!#)"):
    if re.search(pat, text):
        bad.append(f"something to load: {pat}")
if "default-src 'none'" not in text:
    bad.append("no Content-Security-Policy")
# every figure of mech plot, by its title, and no other
titles = []
for f in sorted(os.listdir(figdir)) if os.path.isdir(figdir) else []:  # none: a partial sweep
    t = re.search(r"<title>(.*?)</title>", open(os.path.join(figdir, f)).read()).group(1)
    titles.append(t)
nfig = len(re.findall(r'<figure id="figure-', text))
if nfig != len(titles) and os.path.isdir(figdir):
    bad.append(f"{nfig} figures, mech plot drew {len(titles)}")
for t in titles:
    if f"<title>{t}</title>" not in text:
        bad.append(f"figure '{t}' missing")
# ids unique (the figures' own ids are prefixed)
ids = re.findall(r'\sid="([^"]*)"', text)
if len(ids) != len(set(ids)):
    bad.append("ids repeated: " + str(sorted({i for i in ids if ids.count(i) > 1})[:5]))
# the equations, escaped, and every line of mech check but the file's
eq = open(eqfile).read().split("\n", 1)[1]  # less its title line, which names the file
if esc(eq).strip() not in text:
    bad.append("the text of mech equations is not in the page")
for line in open(checkfile).read().splitlines()[1:]:
    key, value = line.split(None, 1)
    if f"<th>{key}</th><td>{esc(value)}</td>" not in text:
        bad.append(f"mech check's '{key}' line ({value}) not in the page")
interior = 0
for line in open(solveerr).read().splitlines():
    if ": warning: " in line or ": note: " in line or ": error: " in line:
        if esc(line.split(": ", 1)[1]) not in text:
            bad.append(f"message missing: {line}")
    if line.startswith("mech solve: gap: "):
        if f'<li class="error">{esc(line[len("mech solve: "):])}</li>' not in text:
            bad.append(f"gap missing: {line}")
        m = re.match(r"mech solve: gap: rows? ([0-9]+)(?: to ([0-9]+))? of ([0-9]+)", line)
        a, n = int(m.group(1)), int(m.group(3))
        interior += a > 1 and int(m.group(2) or a) < n
# every curve of the first figure breaks at each gap between solved rows
fig = re.search(r'<figure id="figure-1">(.*?)</figure>', text, re.S)
if fig:
    runs = [d.count("M") for d in re.findall(r'<path stroke="[^"]*"[^>]* d="([^"]*)"', fig.group(1))]
    if not runs or any(r != 1 + interior for r in runs):
        bad.append(f"figure 1's curves have {runs} strokes, {1 + interior} expected")
# the slider's rows = mech solve's CSV, bit for bit
data = json.loads(re.search(r'<script type="application/json" id="mech-data">(.*?)</script>',
                            text, re.S).group(1), parse_int=float)  # "-0" stays -0.0
rows = list(csv.reader(open(csvfile)))
head = [h.split(" [")[0] for h in rows[0]]
if [c["name"] for c in data["columns"]] != head:
    bad.append("the page's columns are not the CSV's")
if len(data["rows"]) != len(rows) - 1:
    bad.append(f"{len(data['rows'])} rows behind the slider, the CSV has {len(rows) - 1}")
pack = lambda v: struct.pack("<d", v)
for r in data["rows"]:
    if [pack(v) for v in r[1:]] != [pack(float(v)) for v in rows[1 + int(r[0])]]:
        bad.append(f"row {r[0]} differs from the CSV")
        break
m = re.search(r'id="slider" min="0" max="([0-9]+)"', text)
if not m or int(m.group(1)) != len(data["rows"]) - 1:
    bad.append("the slider's range is not the rows'")
for b in bad:
    print("FAIL:", b)
print(f"checked {page}: {len(titles)} figures, {len(data['rows'])} rows")
sys.exit(1 if bad else 0)
EOF
}

# page_of LABEL YAML ARGS...: the report, mech plot, solve, equations, check
# with the same arguments, then check_page. REPORT_ONLY: more arguments of
# mech report alone (--set); OTHER: the file the other commands read
# instead of YAML (the same file with the parameter replaced); PLOT_ALL=0:
# mech plot without ARGS (it takes no --from/--to; the titles are the same)
page_of() {
    label=$1 yaml=$2
    shift 2
    d=$tmp/$label other=${OTHER:-$yaml}
    mkdir -p "$d"
    rrun "$label: report" "${WANT:-0}" "$MECH" report "$yaml" ${REPORT_ONLY:-} "$@" -o "$d/page.html" || return
    if [ "${PLOT_ALL:-1}" = 1 ]; then
        # (a partial sweep: mech plot draws nothing, exit 1)
        "$MECH" plot "$other" "$@" --out "$d/figs" >/dev/null 2>&1 || [ "${WANT:-0}" = 1 ] ||
            fail "$label: mech plot"
    else
        "$MECH" plot "$other" --out "$d/figs" >/dev/null 2>&1 || fail "$label: mech plot"
    fi
    "$MECH" solve "$other" "$@" -o "$d/solve.csv" 2>"$d/solve.err"
    [ $? = "${WANT:-0}" ] || fail "$label: mech solve"
    "$MECH" equations "$other" >"$d/equations.txt" 2>/dev/null || fail "$label: mech equations"
    "$MECH" check "$other" >"$d/check.txt" 2>/dev/null || fail "$label: mech check"
    if check_page "$d/page.html" "$d/solve.csv" "$d/figs" "$d/equations.txt" "$d/check.txt" \
        "$d/solve.err" >"$d/check.out"; then pass; else fail "$label"; cat "$d/check.out"; fi
}

page_of fourbar $four
full page_of stirling mechanisms/stirling.yaml
full page_of springs mechanisms/spring-slider-crank.yaml
# laws of time with two drivers, gears, loads that depend on the motion: the
# page's structure lines are mech check's (model_describe)
full page_of five-bar mechanisms/five-bar.yaml
full page_of epicyclic mechanisms/epicyclic.yaml
full page_of shaper mechanisms/shaper.yaml --steps 90
page_of conveyor-forces mechanisms/conveyor.yaml --forces --steps 90
PLOT_ALL=0 full page_of slider-range mechanisms/offset-slider-crank.yaml --from 10 --to 100 --steps 9
full page_of outputs mechanisms/watt-six-bar.yaml --outputs B,bellcrank
page_of warnings tests/hard/redundant-parallelogram.yaml
grep -q "warning" "$tmp/warnings/solve.err" && pass || fail "redundant-parallelogram has no warning to show"
# partial sweeps: the page of the rows solved, the gaps listed, exit 1
WANT=1 page_of partial tests/hard/non-grashof-crank.yaml
has_line "$tmp/err" "220 of the sweep's 361 positions were solved; the page shows them" "partial"
WANT=1 full page_of two-intervals tests/hard/non-grashof-two-intervals.yaml
# the animation traces paths (dashed, data-trace) only when no gap would be bridged
traces() { grep -c 'stroke-dasharray="[^"]*" data-trace=' "$1"; }
[ "$(traces "$tmp/fourbar/page.html")" -gt 0 ] && pass || fail "the four-bar's page traces no path"
[ "$(traces "$tmp/partial/page.html")" = 0 ] && pass || fail "a partial page traces paths across its gap"
# --set: the page is that of the file with the parameter replaced
sed 's/^  l: 140 mm /  l: 150 mm /' mechanisms/slider-crank.yaml >"$tmp/slider-crank-150.yaml"
grep -q "l: 150 mm" "$tmp/slider-crank-150.yaml" && pass || fail "slider-crank.yaml has no 'l: 140 mm'"
REPORT_ONLY="--set l=150mm" OTHER=$tmp/slider-crank-150.yaml PLOT_ALL=0 page_of set mechanisms/slider-crank.yaml

# markup in the file's name stays text: the page is well-formed and has
# only its own two </script>
sed 's/^name: .*/name: "Crank <b>rocker<\/b> \& \\"co\\" <\/script><!--"/' $four >"$tmp/markup.yaml"
rrun "markup in the name" 0 "$MECH" report "$tmp/markup.yaml" -o "$tmp/markup.html"
grep -q '<h1>Crank &lt;b&gt;rocker&lt;/b&gt; &amp; &quot;co&quot; &lt;/script&gt;&lt;!--</h1>' \
    "$tmp/markup.html" && pass || fail "the name's markup is not escaped in the heading"
[ "$(grep -c '</script>' "$tmp/markup.html")" = 2 ] && pass || fail "a </script> from the file's name"
python3 -c 'import sys, xml.dom.minidom; xml.dom.minidom.parse(sys.argv[1])' "$tmp/markup.html" &&
    pass || fail "markup in the name: not well-formed"

# --frames: the slider's positions are rows spread evenly
rrun "frames" 0 "$MECH" report $four --frames 5 -o "$tmp/f.html"
rows=$(sed -n 's/^\[\([0-9]*\),.*/\1/p' "$tmp/f.html" | paste -sd, -)
[ "$rows" = "0,90,180,270,360" ] && pass || fail "--frames 5: rows $rows, expected 0,90,180,270,360"
grep -q 'id="slider" min="0" max="4"' "$tmp/f.html" && pass || fail "--frames 5: slider range"

summary
