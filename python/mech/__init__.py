"""mech: planar mechanisms from YAML files, from Python (libmech underneath).

    import mech
    r = mech.solve('mechanisms/fourbar.yaml', from_='0 deg', to='90 deg', steps=90)
    r['B.x']          # numpy float64 array, the same doubles as `mech solve`'s CSV column
    r.columns         # ['q', 'A.x', ...]
    r.units['B.vx']   # 'm/s'
    r.stats           # {'steps': 91, 'iterations': ..., 'worst_residual': ..., ...}

    mech.load(path)   # the model as a dict (SI units)
    mech.check(path)  # the same plus 'structure' (mobility, loops, ...), as `mech check`
    s = mech.sweep(path, {'r': ['30 mm', '40 mm']}, metrics=['range:B.x'])
    s['range:B.x']    # one value per variant, as `mech sweep`'s CSV column

Every function takes set={'name': '45 mm'} to replace the file's parameters.
Errors in the file, its structure or the solve raise MechError, whose message
is the library's, one 'file:line:column: error: message' per line, and whose
.kind says what failed as data ('no-assembly', 'dead-point', 'input', ...: one
of FAIL_KINDS), so that no program has to read the message's words.
See docs/api.md.
"""
import os
import numbers

try:
    from ._mech import MechError, VERSION, EINPUT, ENOMEM, EIO, ESOLVE, FAIL_KINDS
except ModuleNotFoundError as e:
    if e.name != __name__ + '._mech':
        raise

    def _another_python():
        """The extension is here, but for another Python's ABI: say which."""
        import glob
        import os
        import platform
        import sys
        import sysconfig
        here = os.path.dirname(os.path.abspath(__file__))
        found = sorted(os.path.basename(p) for p in glob.glob(os.path.join(here, '_mech*')))
        return ImportError(
            "mech's extension in %s is %s, which is for another Python than this one, %s "
            "(Python %s, which loads _mech%s): build mech for this interpreter: make install "
            "PYTHON=%s, or %s -m pip install --no-build-isolation ./python (docs/api.md, Python)"
            % (here, ', '.join(found) or 'missing', sys.executable, platform.python_version(),
               sysconfig.get_config_var('EXT_SUFFIX'), sys.executable, sys.executable))
    raise _another_python() from None
from . import _mech

__all__ = ['MechError', 'Result', 'SweepResult', 'load', 'check', 'solve', 'simulate', 'sweep',
           'read', 'fit',
           'VERSION',
           'EINPUT', 'ENOMEM', 'EIO', 'ESOLVE', 'FAIL_KINDS', 'VARIANT_STATUS']
__version__ = VERSION


class Result:
    """A solved driver sweep: one numpy array per column, in SI units.

    r[name]     the column as a 1-D float64 array (KeyError for a name not there)
    r.columns   the column names in the CSV's order (the first is 'q', the driver)
    r.units     {name: unit}, e.g. 'm', 'rad/s', 'N', '-'
    r.stats     how the solve went (mech_solve_stats: steps, iterations,
                worst_residual, min_rcond, seconds, ..., failure: 'none' or the
                kind of failure, failure_q: where, in SI)
    r.messages  the library's warnings and notes (dicts like MechError.diagnostics)
    r.nrows     the number of rows (driver positions)
    """

    def __init__(self, names, units, arrays, stats, messages=()):
        self.columns = list(names)
        self.units = dict(zip(names, units))
        self._data = dict(zip(names, arrays))
        self.stats = stats
        self.messages = list(messages)
        self.nrows = len(arrays[0]) if arrays else 0

    def __getitem__(self, name):
        try:
            return self._data[name]
        except KeyError:
            import difflib
            near = difflib.get_close_matches(str(name), self.columns, n=1)
            hint = " (did you mean '%s'?)" % near[0] if near else ''
            raise KeyError("no column '%s'%s" % (name, hint)) from None

    def __contains__(self, name):
        return name in self._data

    def __iter__(self):
        return iter(self.columns)

    def __len__(self):
        return len(self.columns)

    def keys(self):
        return list(self.columns)

    def items(self):
        return [(n, self._data[n]) for n in self.columns]

    def to_array(self):
        """All columns as one (nrows, ncolumns) array, in the order of .columns."""
        import numpy
        return numpy.column_stack([self._data[n] for n in self.columns]) if self.columns \
            else numpy.empty((0, 0))

    def __repr__(self):
        return '<mech.Result: %d rows, %d columns: %s>' % (
            self.nrows, len(self.columns),
            ', '.join(self.columns[:6]) + (', ...' if len(self.columns) > 6 else ''))


def load(path, set=None):
    """The model of a mechanism file as a dict: file, name, description,
    gravity, parameters {name: SI value}, links, points, joints, driver
    (kind, link or joint, positions, from, to, speed, accel; SI; kind 'time'
    for laws of time), drivers (the laws of time: kind, link or joint, law),
    gears (name, kind, links, arm, radii, teeth, internal, pressure_angle)
    and outputs.
    set={'name': 'text'} replaces the file's parameters. Raises MechError."""
    return _mech.load(path, set=set)


def check(path, set=None):
    """load() plus 'structure': links, revolute, prismatic, pin_in_slot,
    unknowns, loops, equations, mobility, drivers, gears (as `mech check`).
    Raises MechError when the file does not load or its structure does not
    check (mobility, connectivity)."""
    return _mech.load(path, set=set, check=True)


def solve(path, set=None, from_=None, to=None, steps=None, outputs=None, forces=None,
          tol=None, level=None, friction=None, diagnostics=False, all=False):
    """Solve the driver sweep of a mechanism file, as `mech solve`.

    from_, to   the driver range instead of the file's: a number in SI (rad
                or m) or a str as on the command line ('30 deg', '0.1 m';
                a bare-number str is degrees or millimetres); together
    steps       intervals (default 360 with from_/to; alone: the file's range)
    outputs     a list of point, link and slider names (or 'A,B,crank')
    forces      True: also joint reactions and driver torque; False: not
                even when the file asks; None: as the file says
    tol         Newton tolerance relative to the largest length (1e-12)
    level       'positions', 'velocities' or 'accelerations' (default)
    friction    'on' (default), 'off' or 'both'
    diagnostics True: add the columns iterations, residual, rcond, substeps
    all         True: solve every unknown, also those no output needs
    set         {'parameter': '45 mm'}: replace the file's parameters (a
                number is a bare number of the file: {'r': 45} is 45 mm in a
                file with units: {length: mm})

    Returns a Result. Raises MechError (with .partial, a Result of the rows
    solved before the failure, when the mechanism cannot be solved), ValueError
    or TypeError for a bad option."""
    try:
        names, units, arrays, stats, messages = _mech.solve(
            path, set=set, from_=from_, to=to, steps=steps, outputs=outputs, forces=forces,
            tol=tol, level=level, friction=friction, diagnostics=diagnostics, all=all)
    except MechError as e:
        if isinstance(getattr(e, 'partial', None), tuple):
            e.partial = Result(*e.partial)
        raise
    return Result(names, units, arrays, stats, messages)


def read(path):
    """Read a table that `mech solve` or `mech simulate` wrote: a CSV, or
    the HDF5 of `-o OUT.h5` (docs/cli.md, HDF5 output), told apart by the
    file's content. Returns a Result (its stats empty) with the file's
    columns, units and numbers as they are in the file. Raises MechError for
    a malformed or unreadable file."""
    names, units, arrays, stats, messages = _mech.read(path)
    return Result(names, units, arrays, stats, messages)


def simulate(path, to=None, step=None, rtol=None, atol=None, method=None, stop_at_rest=False,
             stop_when=None):
    """Forward dynamics of a file with free drivers, as `mech simulate`
    (docs/dynamics.md): the motion the loads give the drivers marked
    `free: true`, integrated by SUNDIALS CVODE.

    to          the last time, s (default: the sweep's last)
    step        the output spacing, s (default: the sweep's)
    rtol, atol  the integration's tolerances (default 1e-8, 1e-10)
    method      'bdf' (default) or 'adams'
    stop_at_rest  True: end where a free driver's rate crosses zero
    stop_when   'NAME.MEMBER=VALUE': end where a point's x or y, a link's
                angle or a slider's s crosses VALUE ('x_C.s=150 mm')

    Returns a Result: 't', the outputs, reactions, driver loads, then
    energy.kinetic, energy.gravity, energy.springs, work.loads,
    work.drivers, work.dampers, energy.balance (J); r.stats has the
    integrator's figures. Raises MechError (with .partial, a Result of the
    rows before, when the run stopped early)."""
    try:
        names, units, arrays, stats, messages = _mech.simulate(
            path, to=to, step=step, rtol=rtol, atol=atol, method=method,
            stop_at_rest=stop_at_rest, stop_when=stop_when)
    except MechError as e:
        if isinstance(getattr(e, 'partial', None), tuple):
            e.partial = Result(*e.partial)
        raise
    return Result(names, units, arrays, stats, messages)


def fit(path, free=None, target=None, starts=None, jobs=None, columns=None, weights=None,
        whole_range=False, free_timing=False, transmission=None):
    """Dimensional synthesis, as `mech fit` (docs/synthesis.md): the values of
    the file's free parameters that make the solved outputs meet the targets,
    by least squares (MINPACK lmder, exact Jacobian, several starts), within
    the bounds and the constraints of the file's `fit:` section.

    free        the parameters to fit: a list of names, each 'NAME' or
                'NAME=LO:HI' ('r=15mm:25mm'), or a str 'r,l=50mm:70mm'
                (default: the fit: section's, with its bounds)
    target      the targets' CSV (default: the fit: section's)
    starts      local fits (default: the section's, else 16 when every free
                parameter has bounds, else 1)
    jobs        worker threads (default: the cores)
    columns     the CSV's columns to fit (default: every one after the first)
    weights     {column: weight} (default 1)
    whole_range, free_timing   as the command's flags
    transmission  (link_a, link_b, min) or 'coupler,rocker,40deg': the least
                angle between two links at every target (default: the
                section's); min a str with its unit or a number of degrees

    Returns a dict: 'params' {name: value in SI}, 'objective' (sum of
    squared weighted residuals, SI), 'worst_error' {column: SI},
    'margins' {constraint: -g in SI, >= 0 met}, 'solves', 'seconds',
    'status' ('converged' or 'not converged'), 'info' (lmder's), 'starts',
    'accepted', 'violated'. Raises MechError for bad input, and with
    status ESOLVE when no start gives a solution (none assembles at every
    target within the constraints)."""
    if free is not None and not isinstance(free, str):
        free = ','.join(free)
    if weights is not None:
        weights = ['%s=%r' % (k, float(v)) for k, v in dict(weights).items()]
    if columns is not None:
        columns = list(columns)
    if transmission is not None and not isinstance(transmission, str):
        a, b, least = transmission
        transmission = '%s,%s,%s' % (a, b, least if isinstance(least, str) else '%rdeg' % float(least))
    return _mech.fit(os.fspath(path), free=free,
                     target=None if target is None else os.fspath(target),
                     columns=columns, weights=weights, starts=starts or 0, jobs=jobs or 0,
                     whole_range=bool(whole_range), free_timing=bool(free_timing),
                     transmission=transmission)


# mech_variant_status, in its order: the status column of `mech sweep`
VARIANT_STATUS = ('ok', 'no-assembly', 'singular', 'self-locking', 'invalid', 'error', 'non-finite')


class SweepResult(Result):
    """A sweep's rows, one per variant, as `mech sweep`'s CSV: columns
    'variant' (int64, its index), one per parameter (float64, SI), 'status'
    (str: 'ok', 'no-assembly', 'singular', 'self-locking', 'invalid',
    'error', 'non-finite'), 'rows' (int64, driver positions solved) and one per metric
    (float64, NaN where the variant was not solved).

    s.messages  {variant index: text} what the load and solve of each variant
                not solved said (`mech sweep` prints the same on stderr)
    s.stats     {'total': variants of the whole grid, 'solved': variants ok,
                'shared': solved through the sweep's one analysis, 'alone':
                analysed on their own}
    s.nrows     the variants of this shard
    """

    def __init__(self, names, units, arrays, status, messages, stats, nparams):
        import numpy
        names, units, arrays = list(names), list(units), list(arrays)
        at = 1 + nparams  # after the variant and its parameters, as in the CSV
        codes = numpy.asarray(status)
        words = numpy.array(VARIANT_STATUS)[codes] if codes.size else numpy.array([], dtype='<U12')
        names.insert(at, 'status')
        units.insert(at, '-')
        arrays.insert(at, words)
        for a in arrays:
            a.setflags(write=False)
        Result.__init__(self, names, units, arrays, stats)
        self.messages = dict(messages)

    def __repr__(self):
        return '<mech.SweepResult: %d variants, %d columns: %s>' % (
            self.nrows, len(self.columns),
            ', '.join(self.columns[:6]) + (', ...' if len(self.columns) > 6 else ''))


def _grid_spec(name, values):
    """(is_list, spec) of one parameter of vary=: a list of values is
    `--list NAME=A,B,...`, a str 'FROM:TO:COUNT' is `--vary NAME=FROM:TO:COUNT`."""
    if not isinstance(name, str):
        raise TypeError('vary: parameter names must be str, not %r' % (name,))
    if isinstance(values, str):
        return (False, '%s=%s' % (name, values))
    texts = []
    for v in values:
        if isinstance(v, str):
            t = v
        elif isinstance(v, numbers.Real) and not isinstance(v, bool):
            t = repr(float(v)) if isinstance(v, float) else repr(int(v))
        else:
            raise TypeError("vary['%s']: a value must be a str like '45 mm' or a number, "
                            'not %r' % (name, v))
        if ',' in t:
            raise ValueError("vary['%s']: the value %r holds a comma" % (name, t))
        texts.append(t)
    return (True, '%s=%s' % (name, ','.join(texts)))


def sweep(path, vary=None, metrics=(), random=None, seed=1, forces=False, jobs=None,
          shard=None, index_offset=0):
    """Solve variants of one mechanism file, as `mech sweep`, each reduced to
    one row (mech_sweep in libmech: the grid, the samples, the metrics and
    the variants on worker threads are the command's own; constant memory
    per variant). Returns a SweepResult, whose columns equal `mech sweep`'s
    CSV columns bit for bit.

    vary        {'r': ['30 mm', '40 mm'], 'l': '130mm:150mm:5'}: a list of
                values (texts as in the file; a number is a bare number of
                the file) as --list, or 'FROM:TO:COUNT' as --vary; every
                combination, the last name varying fastest
    metrics     ['range:B.x', 'maxabs:driver.torque', 'transmission:coupler,rocker',
                'flywheel:0.02', 'max:COL', 'min:COL'] as --metric
    random      N: N variants with every parameter that has a tolerance
                uniform within it (not with vary), seed as --seed
    forces      True: the force analysis in every variant (driver.torque)
    jobs        worker threads (default: the CPUs this process may run on)
    shard       (k, m): only the variants i % m == k, as --shard K/M
    index_offset  number the variants from it, as --index-offset

    A variant that cannot be solved is a row with its status; an invalid
    file, parameter or metric raises MechError (EINPUT), a bad argument
    ValueError or TypeError. The GIL is released while the variants are
    solved."""
    grid = [_grid_spec(n, v) for n, v in (vary or {}).items()]
    if isinstance(metrics, str):
        metrics = [metrics]
    metrics = list(metrics)
    if not all(isinstance(m, str) for m in metrics):
        raise TypeError('metrics: a list of str like "range:B.x"')
    if random is not None and (not isinstance(random, numbers.Integral) or random < 1):
        raise ValueError('random: a number of variants from 1 to 10**7, not %r' % (random,))
    if not isinstance(seed, numbers.Integral) or not 0 <= seed < 2 ** 64:
        raise ValueError('seed: a whole number from 0 to 2**64-1, not %r' % (seed,))
    k, m = shard if shard is not None else (0, 1)
    if not all(isinstance(x, numbers.Integral) for x in (k, m)) or not 0 <= k < m <= 10 ** 6:
        raise ValueError('shard: (k, m) with 0 <= k < m <= 10**6, not %r' % (shard,))
    if not isinstance(index_offset, numbers.Integral) or not 0 <= index_offset <= 10 ** 12:
        raise ValueError('index_offset: a whole number from 0 to 10**12, not %r'
                         % (index_offset,))
    if jobs is not None and (not isinstance(jobs, numbers.Integral) or not 1 <= jobs <= 1024):
        raise ValueError('jobs: a number of workers from 1 to 1024, not %r' % (jobs,))
    return SweepResult(*_mech.sweep(
        path, grid, metrics, random=int(random or 0), seed=int(seed), forces=bool(forces),
        shard=(int(k), int(m)), index_offset=int(index_offset), jobs=int(jobs or 0)))
