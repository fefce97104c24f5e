#!/bin/sh
# tests/python/run.sh: install into an empty temporary prefix and run pytest
# on tests/python/ with the module from that prefix (PYTHONPATH), as a user
# would import it. Run from the repository root (make test-python):
#   BUILD=build PYTHON=/usr/bin/python3 MAKE=make sh tests/python/run.sh
# Under the sanitizers (make test-san) OPT and SAN are passed on to make
# install, and SAN_PRELOAD names the sanitizers' run-time libraries, which
# the uninstrumented python3 loads first (LD_PRELOAD).
NAME=python MECH=${BUILD:-build}/mech . tests/lib.sh
BUILD=${BUILD:-build}
PYTHON=${PYTHON:-python3}
MAKE=${MAKE:-make}
P="$tmp/prefix"
if ! $MAKE --no-print-directory install PREFIX="$P" BUILD="$BUILD" PYTHON="$PYTHON" \
    ${OPT:+OPT="$OPT"} SAN="$SAN" >"$tmp/install.log" 2>&1; then
    fail "make install PREFIX=$P: $(tail -n 5 "$tmp/install.log")"
    summary
    exit
fi
if ! "$PYTHON" -c 'import numpy, pytest' 2>"$tmp/err"; then
    fail "$PYTHON cannot import numpy and pytest (sh tools/deps.sh installs python3-numpy, python3-pytest): $(tail -n 1 "$tmp/err")"
    summary
    exit
fi
pydir=$("$PYTHON" python/buildinfo.py pydir)  # where make install put it for $PYTHON
preload=""
if [ -n "$SAN" ]; then
    for lib in $SAN_PRELOAD; do
        if [ ! -f "$lib" ]; then
            echo "python: note: sanitizer run-time '$lib' not found; pytest skipped under SAN=$SAN"
            summary
            exit
        fi
    done
    preload="$SAN_PRELOAD"
fi
# pytest's exit status: 0 all passed, 1 some failed, 5 no test collected
# (also a failure here), others: usage or internal errors.
LD_PRELOAD="$preload" ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0} PYTHONDONTWRITEBYTECODE=1 \
    MECH="$P/bin/mech" MECH_PREFIX="$P" MECH_PYDIR="$pydir" PYTHONPATH="$P/$pydir" \
    "$PYTHON" -m pytest -q -p no:cacheprovider tests/python >"$tmp/pytest.out" 2>&1
status=$?
tail -n 1 "$tmp/pytest.out" | sed 's/^/python: pytest: /'
if [ "$status" -eq 0 ] && grep -q '[1-9][0-9]* passed' "$tmp/pytest.out"; then pass; else
    fail "pytest exited $status:"
    sed 's/^/    /' "$tmp/pytest.out" | tail -n 60
fi
summary
