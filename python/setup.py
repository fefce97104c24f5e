"""python/setup.py: the module mech built by setuptools for the interpreter
that runs it (pip install ./python; docs/api.md, "Python"). The extension
mech._mech is python/mech_module.c with libmech's own sources (src/*/*.c but
the command line's, src/cli/) compiled in, so it needs no installed libmech, only
Debian's libyaml, SuiteSparse KLU, SUNDIALS CVODE and MINPACK (libcminpack, for
mech.fit); numpy's headers are those of the
running interpreter's numpy (python/buildinfo.py, which the Makefile's
`make install PYTHON=...` uses too), and the extension records what it was
built for, to say so when another interpreter imports it."""
import glob
import os
import re
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import buildinfo  # noqa: E402  (beside this file)


def library_sources():
    """libmech's sources, relative to this directory as setuptools wants
    (their objects go to build/src/ here)."""
    src = sorted(glob.glob(os.path.join(ROOT, 'src', '*', '*.c')))
    lib = [os.path.relpath(f, HERE) for f in src
           if os.path.basename(os.path.dirname(f)) != 'cli']
    if not lib:
        sys.exit("setup.py: no libmech sources in %s: build from the repository's python/ "
                 "directory (pip install ./python)" % os.path.join(ROOT, 'src'))
    return lib


def stage_dirs():
    """src/'s stage folders, whose headers the sources include by name."""
    return sorted(d for d in glob.glob(os.path.join(ROOT, 'src', '*')) if os.path.isdir(d))


def runtime_text():
    """The runtime's text as C arrays for `mech codegen` (the Makefile's
    build/gen/rt_text.c: tools/c_lines.awk over RT_SRC, the list read from
    the Makefile so that it is written once), generated under build/gen/
    here; its path relative to this directory."""
    with open(os.path.join(ROOT, 'Makefile')) as f:
        rt = re.search(r'^RT_SRC\s*=\s*\$\(addprefix src/runtime/,([^)]*)\)$', f.read(), re.M)
    rt_src = [os.path.join('src', 'runtime', h) for h in rt.group(1).split()]
    out_dir = os.path.join(HERE, 'build', 'gen')
    os.makedirs(out_dir, exist_ok=True)
    out = os.path.join(out_dir, 'rt_text.c')
    with open(out + '.tmp', 'w') as f:
        subprocess.run(['awk', '-f', os.path.join(ROOT, 'tools', 'c_lines.awk')] +
                       [os.path.join(ROOT, h) for h in rt_src], stdout=f, check=True)
    os.replace(out + '.tmp', out)
    return os.path.relpath(out, HERE)


def pkg_config(flag, package, fallback):
    try:
        out = subprocess.run(['pkg-config', flag, package], capture_output=True, text=True)
        if out.returncode == 0:
            return out.stdout.split()
    except OSError:
        pass
    return fallback


def version():
    with open(os.path.join(ROOT, 'include', 'mech.h')) as f:
        return re.search(r'^#define MECH_VERSION "([0-9.]+)"$', f.read(), re.M).group(1)


class BuildExt(build_ext):
    """Stops early, saying why, when the interpreter cannot build the module;
    compiles the sources on every core unless told otherwise."""

    def finalize_options(self):
        super().finalize_options()
        if self.parallel is None:
            self.parallel = os.cpu_count() or 1

    def run(self):
        why = buildinfo.problems()
        if why:
            sys.exit("%s cannot build mech's Python module: %s" % (sys.executable, '; '.join(why)))
        super().run()


klu_cflags = pkg_config('--cflags', 'klu', ['-I/usr/include/suitesparse'])
klu_libs = pkg_config('--libs', 'klu', ['-lklu', '-lbtf', '-lamd', '-lcolamd',
                                         '-lsuitesparseconfig'])
yaml_libs = pkg_config('--libs', 'yaml-0.1', ['-lyaml'])
# HDF5's serial flavour, as the Makefile's HDF5_CFLAGS and HDF5_LIBS
hdf5_cflags = pkg_config('--cflags', 'hdf5-serial', ['-I/usr/include/hdf5/serial'])
hdf5_libs = pkg_config('--libs', 'hdf5-serial', ['-lhdf5_serial'])
# GSL, as the Makefile's GSL_LIBS (a cam's profile points, src/load/cam_points.c)
gsl_libs = pkg_config('--libs', 'gsl', ['-lgsl', '-lgslcblas'])


def sundials_libs():
    """SUNDIALS CVODE's libraries for mech_simulate (src/study/simulate.c),
    read from the Makefile's SUNDIALS_LIBS so that they are written once."""
    with open(os.path.join(ROOT, 'Makefile')) as f:
        m = re.search(r'^SUNDIALS_LIBS\s*=\s*((?:.*\\\n)*.*)$', f.read(), re.M)
    return m.group(1).replace('\\\n', ' ').split()


def minpack():
    """MINPACK's flags for mech_fit's lmder (src/study/fit_lm.c): the
    Makefile's MINPACK_CFLAGS and MINPACK_LIBS, pkg-config's cminpack with the
    same fallbacks (Debian's libcminpack-dev)."""
    return (pkg_config('--cflags', 'cminpack', ['-I/usr/include/cminpack-1']),
            pkg_config('--libs', 'cminpack', ['-lcminpack']))


minpack_cflags, minpack_libs = minpack()

extension = Extension(
    'mech._mech',
    sources=['mech_module.c'] + library_sources() + [runtime_text()],
    include_dirs=[os.path.join(ROOT, 'include')] + stage_dirs() + buildinfo.include_dirs(),
    # the extension is built again when a header changes (setuptools looks at
    # the sources' times only)
    depends=[os.path.relpath(h, HERE) for h in [os.path.join(ROOT, 'include', 'mech.h')] +
             sorted(glob.glob(os.path.join(ROOT, 'src', '*', '*.h')))],
    define_macros=buildinfo.define_macros(),
    extra_compile_args=['-std=c11', '-D_POSIX_C_SOURCE=200809L'] + klu_cflags + hdf5_cflags +
    minpack_cflags,
    extra_link_args=yaml_libs + klu_libs + sundials_libs() + hdf5_libs + minpack_libs + gsl_libs +
    ['-lm', '-pthread'],
)

setup(
    version=version(),
    packages=['mech'],
    package_dir={'mech': 'mech'},
    ext_modules=[extension],
    cmdclass={'build_ext': BuildExt},
)
