#!/bin/sh
# tests/api.sh: the C API's contract through build/libmech.so and the public
# header alone (include/mech.h "NULL arguments", "Versions"; docs/api.md,
# "Versions and the ABI"): tests/api_null.c calls every public function with
# NULL wherever allowed and checks the results, the refusals of required
# pointers, the options' size-checked init and mech_version(); then the
# shared library's soname and symbol versions (readelf --dyn-syms): every
# exported function in the node MECH_<major>.<minor> of MECH_VERSION, none
# unversioned, mech_version among them.
# Run from the repository root (make test):  BUILD=build CC=cc sh tests/api.sh
NAME=api MECH=${BUILD:-build}/mech . tests/lib.sh
BUILD=${BUILD:-build}
CC=${CC:-cc}
version=$(sed -n 's/^#define MECH_VERSION "\([0-9][0-9.]*\)"$/\1/p' include/mech.h)
major=${version%%.*}
minor=${version#*.}
minor=${minor%%.*}
node=MECH_$major.$minor
[ "$major" = 0 ] && soname=libmech.so.0.$minor || soname=libmech.so.$major
lib=$BUILD/libmech.so.$version
[ -f "$lib" ] && pass || fail "no $lib (make lib)"

# the contract, through the shared library (run path: the build directory)
# shellcheck disable=SC2086
if $CC $SAN -std=c11 -Wall -Wextra -Werror -pedantic -Iinclude -o "$tmp/api_null" \
        tests/api_null.c -L"$BUILD" -lmech -Wl,-rpath,"$(cd "$BUILD" && pwd)" -lm 2>"$tmp/cc"; then
    pass
    "$tmp/api_null" mechanisms/fourbar.yaml mechanisms/slider-crank.yaml \
        tests/bad/09-unknown-link-key-typo.yaml "$tmp" >"$tmp/out" 2>"$tmp/err"
    status=$?
    grep '^FAIL' "$tmp/out"
    tail -n 1 "$tmp/out"
    [ "$status" = 0 ] && grep -q '^api_null: [0-9]* checks, 0 failed$' "$tmp/out" && pass ||
        fail "api_null exited $status: $(grep -v '^FAIL' "$tmp/err" | head -n 3)"
    has_line "$tmp/out" "^version $version\$" "mech_version()"
    # mech_system_print(s, fmt, NULL) wrote the equations to stdout
    sed -n '/^system to stdout:$/,$p' "$tmp/out" >"$tmp/system"
    has_line "$tmp/system" "unknowns" "mech_system_print(s, fmt, NULL): stdout"
    # the test links the library by its soname
    readelf -d "$tmp/api_null" | grep -q "NEEDED.*\[$soname\]" && pass ||
        fail "api_null does not need $soname: $(readelf -d "$tmp/api_null" | grep NEEDED)"
else
    fail "cc tests/api_null.c: $(head -n 5 "$tmp/cc")"
fi

# the soname and the version node
readelf -d "$lib" | grep -q "SONAME.*\[$soname\]" && pass ||
    fail "soname: $(readelf -d "$lib" | grep SONAME), expected $soname"
readelf -V "$lib" | grep -q "Name: $node\$" && pass ||
    fail "no version definition $node: $(readelf -V "$lib" | grep Name: | head -n 3)"
# every defined function: NAME@@NODE, none unversioned or in another node
readelf --dyn-syms -W "$lib" | awk '$7 != "UND" && $5 == "GLOBAL" && $4 == "FUNC" { print $8 }' \
    >"$tmp/syms"
grep -v "^mech_[a-z_]*@@$node\$" "$tmp/syms" >"$tmp/stray"
[ -s "$tmp/syms" ] && [ ! -s "$tmp/stray" ] && pass ||
    fail "exported functions not in $node: $(head -n 5 "$tmp/stray" | tr '\n' ' ')"
grep -q "^mech_version@@$node\$" "$tmp/syms" && pass || fail "mech_version not exported in $node"
grep -q "^mech_solve_options_init@@$node\$" "$tmp/syms" && pass ||
    fail "mech_solve_options_init not exported in $node"
# every function declared in mech.h is exported (the static inline ones are not)
grep -v '^static' include/mech.h | sed -n 's/^[a-z][a-z_ *]* \**\(mech_[a-z_]*\)(.*/\1/p' |
    sort -u >"$tmp/declared"
sed "s/@@$node\$//" "$tmp/syms" | sort -u >"$tmp/exported"
missing=$(comm -23 "$tmp/declared" "$tmp/exported" | tr '\n' ' ')
[ "$(wc -l <"$tmp/declared")" -gt 30 ] && [ -z "$missing" ] && pass ||
    fail "declared in mech.h, not exported: '$missing' ($(wc -l <"$tmp/declared") declared)"

summary
