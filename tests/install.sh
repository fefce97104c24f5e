#!/bin/sh
# tests/install.sh: `make install` into an empty temporary prefix, then use
# it as a user would: the example of docs/api.md (docs/examples/api_example.c,
# included there verbatim) built with pkg-config alone, against the shared
# library and statically, its numbers against `mech solve`'s CSV, and the
# man page rendered. Run from the repository root (make test-install):
#   BUILD=build CC=cc SAN= MAKE=make sh tests/install.sh
# OPT and SAN are passed on to make install, so a sanitizer build installs
# (and the example links with) the instrumented library.
NAME=install MECH=${BUILD:-build}/mech . tests/lib.sh
BUILD=${BUILD:-build}
CC=${CC:-cc}
MAKE=${MAKE:-make}
P="$tmp/prefix"
export PKG_CONFIG_PATH="$P/lib/pkgconfig"
# the version and soname (docs/api.md, "Versions and the ABI")
version=$(sed -n 's/^#define MECH_VERSION "\([0-9][0-9.]*\)"$/\1/p' include/mech.h)
major=${version%%.*}
minor=${version#*.}
minor=${minor%%.*}
[ "$major" = 0 ] && soname=libmech.so.0.$minor || soname=libmech.so.$major

# 1. the installed tree
if $MAKE --no-print-directory install PREFIX="$P" BUILD="$BUILD" ${OPT:+OPT="$OPT"} SAN="$SAN" \
    >"$tmp/install.log" 2>&1; then pass; else
    fail "make install PREFIX=$P: $(tail -n 5 "$tmp/install.log")"
    summary
    exit
fi
for f in bin/mech include/mech.h lib/libmech.a lib/libmech.so.$version lib/pkgconfig/mech.pc \
    share/man/man1/mech.1 lib/python3/dist-packages/mech/__init__.py; do
    if [ -f "$P/$f" ]; then pass; else fail "not installed: $f"; fi
done
if [ -n "$version" ] && [ "$(readlink "$P/lib/libmech.so")" = "$soname" ] &&
    [ "$(readlink "$P/lib/$soname")" = "libmech.so.$version" ]; then pass; else
    fail "links: libmech.so -> $(readlink "$P/lib/libmech.so"), $soname -> $(readlink "$P/lib/$soname")"
fi
if command -v readelf >/dev/null 2>&1; then
    if readelf -d "$P/lib/libmech.so.$version" | grep -q "SONAME.*\[$soname\]"; then pass; else
        fail "soname: $(readelf -d "$P/lib/libmech.so.$version" | grep SONAME)"
    fi
    # only the API of mech.h is exported (and its version node's name)
    if readelf --dyn-syms -W "$P/lib/libmech.so.$version" | awk '$7 != "UND" && $5 == "GLOBAL" {print $8}' |
        grep -v -e '^mech_' -e '^MECH_[0-9.]*$' | grep . >"$tmp/exported"; then
        fail "exported beyond mech_*: $(head -n 5 "$tmp/exported" | tr '\n' ' ')"
    else pass; fi
fi
if [ "$(pkg-config --modversion mech)" = "$(sed -n 's/^#define MECH_VERSION "\(.*\)"/\1/p' include/mech.h)" ]; then
    pass; else fail "pkg-config --modversion mech: $(pkg-config --modversion mech 2>&1)"; fi

# 2. the example in docs/api.md is docs/examples/api_example.c, verbatim
awk '/^<!-- example: docs\/examples\/api_example.c -->$/ {on = 1; next}
     on && /^```c$/ {code = 1; next}
     code && /^```$/ {exit}
     code {print}' docs/api.md >"$tmp/api_example.c"
if [ -s "$tmp/api_example.c" ] && cmp -s "$tmp/api_example.c" docs/examples/api_example.c; then pass; else
    fail "docs/api.md's example differs from docs/examples/api_example.c: $(diff "$tmp/api_example.c" docs/examples/api_example.c | head -n 5)"
fi

# 3. built with pkg-config alone (shared), run against the installed library
# shellcheck disable=SC2046,SC2086
if $CC $SAN -std=c11 -Wall -Wextra -Werror -o "$tmp/example" "$tmp/api_example.c" \
    $(pkg-config --cflags --libs mech) 2>"$tmp/cc.err"; then pass; else
    fail "cc api_example.c \$(pkg-config --cflags --libs mech): $(head -n 5 "$tmp/cc.err")"
fi

# columns NAME... of a mech solve CSV (stdin), the driver column first
csv_columns() {
    awk -F, -v want="$*" 'NR == 1 {
            n = split(want, w, " "); sel[0] = 1
            for (i = 1; i <= n; i++) for (j = 1; j <= NF; j++) {
                h = $j; sub(/ \[.*$/, "", h); if (h == w[i]) sel[i] = j }
        }
        { line = $sel[0]; for (i = 1; i <= n; i++) line = line "," (sel[i] ? $sel[i] : "MISSING"); print line }'
}

# check_numbers LABEL EXE FILE COLUMN...: the example's output (%.17g) holds
# the same doubles as the same columns of `mech solve FILE` (the shortest
# text that reads back): equal when read, rtol 0 atol 0
check_numbers() {
    label=$1 exe=$2 file=$3
    shift 3
    if ! env LD_LIBRARY_PATH="$P/lib" "$exe" "$file" "$@" >"$tmp/ex.csv" 2>"$tmp/ex.err"; then
        fail "$label: $exe $file exited $? ($(head -n 2 "$tmp/ex.err"))"
        return
    fi
    "$P/bin/mech" solve "$file" -o "$tmp/solve.csv" 2>"$tmp/solve.err"
    csv_columns "$@" <"$tmp/solve.csv" >"$tmp/want.csv"
    if [ "$(wc -l <"$tmp/ex.csv")" -gt 10 ] &&
        "$P/bin/mech" compare "$tmp/ex.csv" "$tmp/want.csv" --rtol 0 --atol 0 >/dev/null 2>&1; then pass; else
        fail "$label: $file $*: example and mech solve differ: $(diff "$tmp/ex.csv" "$tmp/want.csv" | head -n 4)"
    fi
}

if [ -x "$tmp/example" ]; then
    # the shared library is the one installed, found by LD_LIBRARY_PATH
    if command -v ldd >/dev/null 2>&1; then
        if LD_LIBRARY_PATH="$P/lib" ldd "$tmp/example" | grep -q "$soname => $P/lib/$soname"; then
            pass; else fail "example not linked with $P/lib/$soname: $(LD_LIBRARY_PATH="$P/lib" ldd "$tmp/example" | grep mech)"; fi
    fi
    check_numbers "shared" "$tmp/example" mechanisms/fourbar.yaml B.x B.vx B.ay coupler.omega rocker.alpha
    check_numbers "shared" "$tmp/example" mechanisms/stirling.yaml D.x L.vy J.ay link4.angle
    check_numbers "shared" "$tmp/example" mechanisms/slider-crank.yaml B.x B.ax
    # an error: file:line:column on stderr, exit 2
    env LD_LIBRARY_PATH="$P/lib" "$tmp/example" tests/bad/09-unknown-link-key-typo.yaml >"$tmp/out" 2>"$tmp/err"
    status=$?
    if [ "$status" -eq 2 ] && grep -q '^tests/bad/09-unknown-link-key-typo.yaml:[0-9]*:[0-9]*: error: ' "$tmp/err"; then
        pass; else fail "example on a bad file: exit $status, stderr $(head -n 1 "$tmp/err")"; fi
fi

# 4. statically: pkg-config --static gives every library libmech needs
# (Libs.private, Requires.private); -static takes libmech.a. Not under the
# sanitizers, whose runtimes are shared libraries.
if [ -z "$SAN" ]; then
    # shellcheck disable=SC2046
    if $CC -static -std=c11 -o "$tmp/example-static" "$tmp/api_example.c" \
        $(pkg-config --static --cflags --libs mech) 2>"$tmp/cc.err"; then
        pass
        check_numbers "static" "$tmp/example-static" mechanisms/fourbar.yaml B.x coupler.omega
    else
        fail "cc -static api_example.c \$(pkg-config --static --cflags --libs mech): $(grep -v 'warning' "$tmp/cc.err" | head -n 3)"
    fi
fi

# 5. the man page renders, without groff warnings, and covers every command
man_page="$P/share/man/man1/mech.1"
if command -v man >/dev/null 2>&1; then
    MANWIDTH=80 MAN_KEEP_FORMATTING= man --warnings=all -l "$man_page" >"$tmp/man.txt" 2>"$tmp/man.err"
    how="man -l"
elif command -v groff >/dev/null 2>&1; then
    groff -man -Tutf8 -ww "$man_page" >"$tmp/man.txt" 2>"$tmp/man.err"
    how="groff -man"
else
    how=""
    echo "install: note: neither man nor groff is installed; the man page was not rendered"
fi
if [ -n "$how" ]; then
    if [ -s "$tmp/man.txt" ] && [ ! -s "$tmp/man.err" ]; then pass; else
        fail "$how $man_page: $(head -n 3 "$tmp/man.err")"; fi
    sed 's/.\x08//g' "$tmp/man.txt" >"$tmp/man.plain"
    for c in check equations solve compare batch sweep merge plot animate codegen report fit; do
        has_line "$tmp/man.plain" "^ *mech $c " "man page: section of mech $c"
    done
    for h in SYNOPSIS 'EXIT STATUS' FILES; do
        has_line "$tmp/man.plain" "^$h" "man page: $h"
    done
    # every option of every command's --help is in the man page
    for c in check equations solve compare batch sweep merge plot animate codegen report fit; do
        "$P/bin/mech" "$c" --help | grep -o -- '--[a-z][a-z-]*' | sort -u | while read -r opt; do
            grep -q -- "$opt" "$tmp/man.plain" || echo "$c $opt"
        done
    done >"$tmp/missing"
    if [ -s "$tmp/missing" ]; then fail "man page lacks options: $(tr '\n' ' ' <"$tmp/missing")"; else pass; fi
fi

summary
