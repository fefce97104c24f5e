#!/bin/sh
# tests/python/interpreters.sh: the module mech built for the interpreter
# that is to import it, not only for Debian's python3 (docs/api.md,
# "Python"; issue 32 point 12):
#  1. built for $PYTHON (make install), imported by another interpreter
#     that lacks numpy (a venv without the system's packages): an
#     ImportError naming the interpreter and numpy it was built for, the
#     one running, and how to build it for that one; by a Python of another
#     minor version (a pyenv one, when there is one): an ImportError naming
#     the extension file found and the one that Python loads;
#  2. make install PYTHON=VENV-PYTHON (a venv with the system's numpy):
#     built for the venv's interpreter, installed in its site directory
#     under the prefix, the same numbers as `mech solve`;
#  3. pip install --no-build-isolation ./python, offline (no index), by a
#     pyenv python (when there is one; else the venv's): built by and for
#     that interpreter, with its numpy, from a copy of the tree.
# The pyenv pythons here have no numpy and no wheel, and none can be
# fetched: they are given Debian's (the same CPython ABI for the same minor
# version) through PYTHONPATH, a directory holding only those two.
# Run from the repository root (make test-python):
#   BUILD=build PYTHON=/usr/bin/python3 MAKE=make sh tests/python/interpreters.sh
NAME=interpreters MECH=${BUILD:-build}/mech . tests/lib.sh
BUILD=${BUILD:-build}
PYTHON=${PYTHON:-python3}
MAKE=${MAKE:-make}

if ! "$PYTHON" python/buildinfo.py check >"$tmp/built-for" 2>"$tmp/err"; then
    fail "$(cat "$tmp/err")"
    summary
    exit
fi
read -r _ built_exe built_version _ built_numpy <"$tmp/built-for"
minor=$("$PYTHON" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
npdir=$("$PYTHON" -c 'import numpy, os; print(os.path.dirname(os.path.dirname(numpy.__file__)))')

# the numbers of a module against the command line: B.x of the four-bar,
# bit for bit, read-only; prints the interpreter the module was built for
cat >"$tmp/smoke.py" <<'EOF'
import subprocess, sys
import numpy as np
import mech
r = mech.solve('mechanisms/fourbar.yaml', outputs='B')
csv = subprocess.run([sys.argv[1], 'solve', 'mechanisms/fourbar.yaml', '--outputs', 'B', '-q',
                      '-o', '-'], check=True, capture_output=True, text=True).stdout.splitlines()
bx = np.array([float(l.split(',')[1]) for l in csv[1:]])
assert r.nrows == 361 and (r['B.x'].view(np.uint64) == bx.view(np.uint64)).all(), 'B.x differs'
assert not r['B.x'].flags.writeable, 'a writable column'
print(mech._mech.BUILT_FOR['python'], mech._mech.BUILT_FOR['numpy'], mech.__file__)
EOF

# ---- 1. the import errors ----
P=$tmp/prefix
if $MAKE --no-print-directory install PREFIX="$P" BUILD="$BUILD" PYTHON="$PYTHON" \
        ${OPT:+OPT="$OPT"} SAN="$SAN" >"$tmp/install.log" 2>&1; then
    pass
else
    fail "make install PYTHON=$PYTHON: $(tail -n 3 "$tmp/install.log")"
fi
pydir=$("$PYTHON" python/buildinfo.py pydir)
"$PYTHON" -m venv "$tmp/bare" >"$tmp/err" 2>&1 || fail "python3 -m venv: $(cat "$tmp/err")"
PYTHONPATH=$P/$pydir "$tmp/bare/bin/python" -c 'import mech' >"$tmp/out" 2>&1
if [ $? -ne 0 ] && grep -q "ImportError: mech's extension was built for $built_exe (Python $built_version) with numpy $built_numpy; this is $tmp/bare/bin/python (Python [0-9.]*) with no numpy.*make install PYTHON=$tmp/bare/bin/python, or $tmp/bare/bin/python -m pip install --no-build-isolation ./python" "$tmp/out"; then
    pass
else
    fail "import by an interpreter without numpy: $(tail -n 1 "$tmp/out")"
fi
other=""
for p in "$HOME"/.pyenv/versions/3.*/bin/python3; do
    [ -x "$p" ] && [ "$("$p" -c 'import sys; print("%d.%d" % sys.version_info[:2])')" != "$minor" ] &&
        other=$p && break
done
if [ -n "$other" ]; then
    PYTHONPATH=$P/$pydir "$other" -c 'import mech' >"$tmp/out" 2>&1
    if [ $? -ne 0 ] && grep -q "ImportError: mech's extension in $P/$pydir/mech is _mech\.cpython-.*, which is for another Python than this one, $other (Python .*, which loads _mech\.cpython-.*make install PYTHON=$other" "$tmp/out"; then
        pass
    else
        fail "import by $other: $(tail -n 1 "$tmp/out")"
    fi
else
    echo "interpreters: no Python of another minor version than $minor here: that import not tried"
fi

# ---- 2. make install PYTHON=: a venv's interpreter ----
"$PYTHON" -m venv --system-site-packages "$tmp/venv" >"$tmp/err" 2>&1 ||
    fail "python3 -m venv --system-site-packages: $(cat "$tmp/err")"
V=$tmp/vprefix
vpy=$tmp/venv/bin/python
if $MAKE --no-print-directory install PREFIX="$V" BUILD="$BUILD" PYTHON="$vpy" \
        ${OPT:+OPT="$OPT"} SAN="$SAN" >"$tmp/install.log" 2>&1; then
    vdir=$("$vpy" python/buildinfo.py pydir)
    [ "$vdir" = "lib/python$minor/site-packages" ] && pass || fail "the venv's pydir: $vdir"
    if PYTHONPATH=$V/$vdir "$vpy" "$tmp/smoke.py" "$BUILD/mech" >"$tmp/out" 2>&1 &&
            [ "$(cut -d' ' -f1,2 "$tmp/out")" = "$vpy $built_numpy" ]; then
        pass
    else
        fail "make install PYTHON=$vpy: $(tail -n 2 "$tmp/out")"
    fi
else
    fail "make install PYTHON=$vpy: $(tail -n 3 "$tmp/install.log")"
fi
# an interpreter that cannot build it: make says why and stops
$MAKE --no-print-directory python BUILD="$BUILD" PYTHON="$tmp/bare/bin/python" >"$tmp/out" 2>&1
[ $? -ne 0 ] && has_line "$tmp/out" "$tmp/bare/bin/python cannot build mech's Python module: no numpy" \
    "make python PYTHON=an interpreter without numpy"
# and the build for $PYTHON again, as the other suites expect it
$MAKE --no-print-directory python BUILD="$BUILD" PYTHON="$PYTHON" >/dev/null 2>&1 && pass ||
    fail "make python PYTHON=$PYTHON again"

# ---- 3. pip install --no-build-isolation ./python, offline ----
pip_py=""
for p in "$HOME"/.pyenv/versions/$minor*/bin/python3; do
    [ -x "$p" ] && "$p" -m pip --version >/dev/null 2>&1 && pip_py=$p && break
done
mkdir -p "$tmp/given"
if [ -n "$pip_py" ]; then
    # Debian's numpy and wheel only, with their metadata (setuptools finds
    # bdist_wheel by wheel's entry points); its pip and setuptools stay its own
    for m in "$npdir"/numpy "$npdir"/numpy-*info "$npdir"/wheel "$npdir"/wheel-*info; do
        [ -e "$m" ] && ln -s "$m" "$tmp/given/"
    done
    echo "interpreters: pip install by $pip_py (numpy, wheel from $npdir)"
else
    pip_py=$vpy
    echo "interpreters: no pyenv python $minor with pip here: pip install by the venv's $vpy"
fi
mkdir -p "$tmp/tree" "$tmp/site"
cp -r python src include tools Makefile "$tmp/tree/"
rm -rf "$tmp/tree/python/build" "$tmp/tree/python/"*.egg-info
if PYTHONPATH=$tmp/given PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 nice "$pip_py" -m pip \
        install --no-build-isolation --no-deps --target "$tmp/site" "$tmp/tree/python" \
        >"$tmp/pip.log" 2>&1; then
    pass
    if PYTHONPATH=$tmp/given:$tmp/site "$pip_py" "$tmp/smoke.py" "$BUILD/mech" >"$tmp/out" 2>&1 &&
            [ "$(cut -d' ' -f1,2 "$tmp/out")" = "$pip_py $built_numpy" ] &&
            grep -q " $tmp/site/mech/__init__.py\$" "$tmp/out"; then
        pass
    else
        fail "pip install by $pip_py: $(tail -n 2 "$tmp/out")"
    fi
else
    fail "pip install --no-build-isolation by $pip_py: $(grep -i error "$tmp/pip.log" | head -n 3)"
fi

summary
