"""mech: planar mechanisms from YAML files, from Python (libmech underneath).

    import mech
    r = mech.solve('mechanisms/fourbar.yaml', from_='0 deg', to='90 deg', steps=90)
    r['B.x']          # numpy float64 array, the same doubles as `mech solve`'s CSV column
    r.columns         # ['q', 'A.x', ...]
    r.units['B.vx']   # 'm/s'
    r.stats           # {'steps': 91, 'iterations': ..., 'worst_residual': ..., ...}

    mech.load(path)   # the model as a dict (SI units)
    mech.check(path)  # the same plus 'structure' (mobility, loops, ...), as `mech check`
    mech.sweep(path, {'r': ['30 mm', '40 mm']})   # one solve per variant

Every function takes set={'name': '45 mm'} to replace the file's parameters.
Errors in the file, its structure or the solve raise MechError, whose message
is the library's, one 'file:line:column: error: message' per line.
See docs/api.md.
"""
import itertools
from concurrent.futures import ThreadPoolExecutor

from ._mech import MechError, VERSION, EINPUT, ENOMEM, EIO, ESOLVE
from . import _mech

__all__ = ['MechError', 'Result', 'load', 'check', 'solve', 'sweep', 'VERSION',
           'EINPUT', 'ENOMEM', 'EIO', 'ESOLVE']
__version__ = VERSION


class Result:
    """A solved driver sweep: one numpy array per column, in SI units.

    r[name]     the column as a 1-D float64 array (KeyError for a name not there)
    r.columns   the column names in the CSV's order (the first is 'q', the driver)
    r.units     {name: unit}, e.g. 'm', 'rad/s', 'N', '-'
    r.stats     how the solve went (mech_solve_stats: steps, iterations,
                worst_residual, min_rcond, seconds, ...)
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


def sweep(path, vary, jobs=None, **options):
    """Solve every combination of parameter values: vary={'r': ['30 mm',
    '40 mm'], 'l': [100, 120]} (texts as in the file; a number is a bare
    number of the file, which takes the file's unit where it is used).
    options are solve()'s (set= gives fixed overrides). Returns one dict per
    variant, in the order of the grid (the last name varies fastest):
    {'set': {...}, 'ok': bool, 'result': Result or None, 'error': MechError
    or None}. A variant that cannot be solved is reported, not raised; an
    invalid file or option raises as solve() does (for the first variant).
    jobs: worker threads (default: as many as variants, at most 8); the
    library releases the GIL while it solves."""
    names = list(vary)
    fixed = dict(options.pop('set', None) or {})
    grid = [dict(zip(names, values)) for values in itertools.product(*(vary[n] for n in names))]

    def one(values):
        overrides = dict(fixed)
        overrides.update(values)
        try:
            return {'set': values, 'ok': True, 'result': solve(path, set=overrides, **options),
                    'error': None}
        except MechError as e:
            if e.status != ESOLVE:
                raise
            return {'set': values, 'ok': False, 'result': None, 'error': e}

    if not grid:
        return []
    workers = jobs if jobs else min(len(grid), 8)
    if workers <= 1:
        return [one(v) for v in grid]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(one, grid))
