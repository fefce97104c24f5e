"""python/buildinfo.py: what the module mech is built for, asked of the
interpreter that runs this file (docs/api.md, "Python"). The Makefile runs
it with $(PYTHON) and python/setup.py imports it, so that both build the
extension for one interpreter: its headers, its numpy, its extension
suffix, its directory under a prefix, and what the extension says it was
built for when another interpreter imports it.

    python3 python/buildinfo.py check     one line: the interpreter, its
                                          version and numpy's; exit 1 with
                                          why when it cannot build mech
    python3 python/buildinfo.py cflags    -I... for Python.h and numpy
    python3 python/buildinfo.py defines   -DMECH_BUILT_...=... (shell-quoted)
    python3 python/buildinfo.py suffix    the extension suffix (.cpython-311-...so)
    python3 python/buildinfo.py pydir     the module directory under a prefix
"""
import os
import platform
import shlex
import sys
import sysconfig


def numpy_or_none():
    try:
        import numpy
    except ImportError:
        return None
    return numpy


def problems():
    """Why this interpreter cannot build the extension (empty: it can)."""
    why = []
    if not os.path.exists(os.path.join(sysconfig.get_paths()['include'], 'Python.h')):
        why.append("no Python.h in %s (Debian: python3-dev)" % sysconfig.get_paths()['include'])
    if numpy_or_none() is None:
        why.append("no numpy (Debian: python3-numpy; or pip install numpy for it)")
    return why


def built_for():
    """(interpreter, Python version, numpy version): what the extension says."""
    np = numpy_or_none()
    return sys.executable, platform.python_version(), np.__version__ if np else 'none'


def include_dirs():
    np = numpy_or_none()
    return [sysconfig.get_paths()['include']] + ([np.get_include()] if np else [])


def c_string(text):
    return '"%s"' % text.replace('\\', '\\\\').replace('"', '\\"')


def define_macros():
    exe, version, npv = built_for()
    return [('MECH_BUILT_PYTHON', c_string(exe)), ('MECH_BUILT_PYTHON_VERSION', c_string(version)),
            ('MECH_BUILT_NUMPY', c_string(npv))]


def pydir():
    """Where the package goes under a prefix P: Debian's interpreter keeps
    P/lib/python3/dist-packages (the place of Debian's modules), any other
    its own site directory (lib/pythonX.Y/site-packages)."""
    if sysconfig.get_default_scheme() in ('posix_local', 'deb_system'):
        return 'lib/python3/dist-packages'
    path = sysconfig.get_path('platlib', 'posix_prefix', {'platbase': '/P', 'base': '/P'})
    return os.path.relpath(path, '/P')


def main(what):
    if what == 'check':
        why = problems()
        if why:
            sys.exit("%s cannot build mech's Python module: %s" % (sys.executable, '; '.join(why)))
        print('python %s %s numpy %s' % built_for())
    elif what == 'cflags':
        print(' '.join('-I' + shlex.quote(d) for d in include_dirs()))
    elif what == 'defines':
        print(' '.join(shlex.quote('-D%s=%s' % m) for m in define_macros()))
    elif what == 'suffix':
        print(sysconfig.get_config_var('EXT_SUFFIX') or '.so')
    elif what == 'pydir':
        print(pydir())
    else:
        sys.exit('usage: buildinfo.py check|cflags|defines|suffix|pydir')


if __name__ == '__main__':
    main(sys.argv[1] if len(sys.argv) == 2 else '')
