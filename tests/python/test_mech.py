"""tests/python/test_mech.py: the Python module `mech` against the `mech`
command (docs/api.md, "Python"). Run by tests/python/run.sh (make test),
which installs into a temporary prefix and sets PYTHONPATH, MECH (the
installed command) and MECH_PREFIX; run from the repository root."""
import glob
import math
import os
import re
import subprocess
import threading

import numpy as np
import pytest

import mech

MECH = os.environ.get('MECH', 'build/mech')
MECHANISMS = sorted(glob.glob('mechanisms/*.yaml'))
BAD = sorted(glob.glob('tests/bad/*.yaml'))


def cli_csv(path, *args):
    """`mech solve path args` as (names, units, {name: array}) from its CSV."""
    out = subprocess.run([MECH, 'solve', path, *args], check=True, capture_output=True,
                         text=True).stdout
    lines = [l for l in out.splitlines() if l and not l.startswith('#')]
    header = lines[0].split(',')
    names = [h[:h.index(' [')] for h in header]
    units = [h[h.index(' [') + 2:-1] for h in header]
    rows = [[float(x) for x in l.split(',')] for l in lines[1:]]
    data = np.array(rows, dtype=np.float64).reshape(len(rows), len(names))
    return names, units, {n: data[:, i].copy() for i, n in enumerate(names)}


def assert_bits_equal(a, b, what):
    """Equal bit for bit (so nan equals nan, and -0.0 differs from 0.0)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    assert a.shape == b.shape, what
    same = a.view(np.uint64) == b.view(np.uint64)
    # the CSV prints every nan as 'nan' or '-nan': compare nans by being nan
    same |= np.isnan(a) & np.isnan(b)
    assert same.all(), '%s: first difference at row %d: %r vs %r' % (
        what, int(np.argmin(same)), a[~same][0], b[~same][0])


def assert_same_as_cli(r, path, *args):
    names, units, data = cli_csv(path, *args)
    assert r.columns == names
    assert [r.units[n] for n in names] == units
    assert r.nrows == len(data[names[0]])
    for n in names:
        assert r[n].dtype == np.float64
        assert_bits_equal(r[n], data[n], '%s %s' % (path, n))


def test_imported_from_the_install_prefix():
    prefix = os.environ.get('MECH_PREFIX')
    pydir = os.environ.get('MECH_PYDIR', 'lib/python3/dist-packages')
    if prefix:
        assert os.path.realpath(mech.__file__).startswith(
            os.path.realpath(os.path.join(prefix, pydir, 'mech')))
    assert re.fullmatch(r'\d+\.\d+\.\d+', mech.__version__)
    # built for this interpreter and its numpy
    import platform
    import sys
    assert mech._mech.BUILT_FOR == {'python': sys.executable,
                                    'python_version': platform.python_version(),
                                    'numpy': np.__version__}


@pytest.mark.parametrize('path', MECHANISMS)
def test_solve_equals_the_csv_bit_for_bit(path):
    r = mech.solve(path)
    assert_same_as_cli(r, path)
    assert r.stats['steps'] == r.nrows
    # a gear train with no loop is linear: its predictor is exact, Newton
    # has nothing to do (docs/format.md 6.4)
    if mech.check(path)['structure']['loops'] > 0:
        assert r.stats['iterations'] >= r.nrows
    assert r.stats['worst_residual'] < 1e-9


def test_options_as_the_command_line():
    path = 'mechanisms/fourbar.yaml'
    r = mech.solve(path, from_='30 deg', to='90 deg', steps=12, outputs=['B', 'coupler'])
    assert_same_as_cli(r, path, '--from', '30deg', '--to', '90deg', '--steps', '12',
                       '--outputs', 'B,coupler')
    assert r.columns[:3] == ['q', 'B.x', 'B.y']
    assert r.nrows == 13
    assert r['q'][0] == math.radians(30) or abs(r['q'][0] - math.radians(30)) < 1e-15
    # numbers are SI
    r2 = mech.solve(path, from_=math.radians(30), to=math.radians(90), steps=12,
                    outputs='B,coupler')
    assert_same_as_cli(r2, path, '--from', repr(math.radians(30)) + 'rad', '--to',
                       repr(math.radians(90)) + 'rad', '--steps', '12', '--outputs', 'B,coupler')
    # steps alone: a new spacing of the file's range
    r3 = mech.solve(path, steps=10)
    assert_same_as_cli(r3, path, '--steps', '10')


def test_tol_level_diagnostics():
    path = 'mechanisms/stirling.yaml'
    r = mech.solve(path, tol=1e-10, level='velocities', diagnostics=True)
    assert_same_as_cli(r, path, '--tol', '1e-10', '--level', 'velocities', '--diagnostics')
    assert 'rcond' in r and not any(c.endswith('.ax') for c in r.columns)


def test_forces():
    path = 'mechanisms/slider-crank.yaml'
    r = mech.solve(path, forces=True)
    assert_same_as_cli(r, path, '--forces')
    assert any(c.startswith('driver.') for c in r.columns)
    # forces=False: not even when the file asks
    plain = mech.solve(path, forces=False)
    assert not any(c.startswith('driver.') for c in plain.columns)


def test_parameter_overrides():
    path = 'mechanisms/slider-crank.yaml'
    r = mech.solve(path, set={'r': '45 mm'})
    assert_same_as_cli(r, path, '--set', 'r=45 mm')
    assert mech.load(path, set={'r': '45 mm'})['parameters']['r'] == pytest.approx(0.045)
    # a number is a bare number of the file (here: mm, the file's length unit)
    assert_bits_equal(mech.solve(path, set={'r': 45})['B.x'], r['B.x'], 'set r=45')
    with pytest.raises(mech.MechError) as e:
        mech.solve(path, set={'nosuch': '1 mm'})
    assert 'nosuch' in str(e.value) and e.value.status == mech.EINPUT


def test_load_and_check():
    m = mech.load('mechanisms/fourbar.yaml')
    assert m['name'] == 'Crank-rocker four-bar'
    assert m['links'][0] == 'ground' and 'coupler' in m['links']
    assert m['driver']['kind'] == 'angle' and m['driver']['link'] == 'crank'
    assert m['driver']['to'] == pytest.approx(2 * math.pi)
    assert 'structure' not in m
    c = mech.check('mechanisms/fourbar.yaml')
    assert c['structure'] == {'links': 4, 'revolute': 4, 'prismatic': 0, 'pin_in_slot': 0,
                              'unknowns': 2, 'loops': 1, 'equations': 2, 'mobility': 1,
                              'drivers': 1, 'gears': 0}
    assert m['drivers'] == [] and m['gears'] == []
    for path in MECHANISMS:
        s = mech.check(path)['structure']
        assert s['mobility'] == s['drivers'], path


@pytest.mark.parametrize('path', BAD)
def test_errors_carry_file_line_column(path):
    cli = subprocess.run([MECH, 'solve', path, '-o', os.devnull], capture_output=True, text=True)
    assert cli.returncode == 2
    with pytest.raises(mech.MechError) as e:
        mech.solve(path)
    # the same messages as the command prints, file:line:column first
    assert str(e.value) + '\n' == cli.stderr
    assert e.value.status == mech.EINPUT
    assert e.value.diagnostics and e.value.diagnostics[0]['file'] == path
    first = str(e.value).splitlines()[0]
    assert re.match(re.escape(path) + r'(:\d+:\d+)?: error: ', first), first
    with pytest.raises(mech.MechError):
        mech.check(path)


def test_error_line_and_column():
    with pytest.raises(mech.MechError) as e:
        mech.load('tests/bad/09-unknown-link-key-typo.yaml')
    assert re.match(r"tests/bad/09-unknown-link-key-typo\.yaml:\d+:\d+: error: unknown key 'mas'",
                    str(e.value))
    d = e.value.diagnostics[0]
    assert d['line'] > 0 and d['column'] > 0 and d['severity'] == 'error'
    assert "did you mean 'mass'" in d['message']


def test_missing_file():
    with pytest.raises(mech.MechError) as e:
        mech.load('tests/no-such-file.yaml')
    assert e.value.status == mech.EIO and 'no-such-file.yaml' in str(e.value)


def test_solve_failure_keeps_the_rows_solved():
    path = 'tests/solve/non-grashof.yaml'
    with pytest.raises(mech.MechError) as e:
        mech.solve(path)
    assert e.value.status == mech.ESOLVE
    assert re.match(re.escape(path) + r':\d+:\d+: error: cannot assemble', str(e.value))
    partial = e.value.partial
    assert isinstance(partial, mech.Result) and 0 < partial.nrows < 361


def test_error_kinds():
    """MechError.kind says what failed as data, from the library's failure
    kinds (mech_fail_kind), not from the message's words."""
    assert mech.FAIL_KINDS[:5] == ('none', 'input', 'io', 'no-memory', 'no-assembly')
    cases = [('tests/solve/non-grashof.yaml', 'no-assembly'),
             ('tests/solve/dead-centre.yaml', 'dead-point'),
             ('tests/hard/change-point.yaml', 'change-point'),
             # issue 32 point 10: a crank far too long cannot assemble; it is
             # not a singular position
             ('tests/solve/crank-too-long.yaml', 'no-assembly')]
    for path, kind in cases:
        with pytest.raises(mech.MechError) as e:
            mech.solve(path)
        assert e.value.status == mech.ESOLVE and e.value.kind == kind, (path, e.value.kind)
        errors = [d for d in e.value.diagnostics if d['severity'] == 'error']
        assert errors[0]['kind'] == kind
        assert e.value.partial.stats['failure'] == kind
    with pytest.raises(mech.MechError) as e:
        mech.solve('tests/solve/crank-too-long.yaml')
    assert 'coupler and rocker' in str(e.value) and 'singular' not in str(e.value)
    assert e.value.partial.stats['failure_q'] == 0.0
    with pytest.raises(mech.MechError) as e:
        mech.load('tests/no-such-file.yaml')
    assert e.value.kind == 'io'
    with pytest.raises(mech.MechError) as e:
        mech.load('tests/bad/09-unknown-link-key-typo.yaml')
    assert e.value.kind == 'input' and e.value.diagnostics[0]['kind'] == 'input'
    with pytest.raises(mech.MechError) as e:
        mech.solve('mechanisms/fourbar.yaml', outputs=['Bee'])
    assert e.value.kind == 'input'
    r = mech.solve('mechanisms/fourbar.yaml')
    assert r.stats['failure'] == 'none' and np.isnan(r.stats['failure_q'])
    # a sweep's status column comes from the kinds (mech.VARIANT_STATUS)
    s = mech.sweep('tests/solve/crank-too-long.yaml', {'r': ['20 mm', '200 mm']}, jobs=1)
    assert list(s['status']) == ['ok', 'no-assembly']


def test_bad_options():
    path = 'mechanisms/fourbar.yaml'
    with pytest.raises(ValueError):
        mech.solve(path, from_='0 deg')
    with pytest.raises(ValueError):
        mech.solve(path, steps=0)
    with pytest.raises(ValueError):
        mech.solve(path, from_='0 parsec', to='1 deg')
    with pytest.raises(ValueError):
        mech.solve(path, level='jerk')
    with pytest.raises(ValueError):
        mech.solve(path, tol=2.0)
    with pytest.raises(TypeError):
        mech.solve(path, set={'r': [1]})
    with pytest.raises(mech.MechError) as e:
        mech.solve(path, outputs=['Bee'])
    assert "'Bee'" in str(e.value) and e.value.status == mech.EINPUT


def test_result_mapping():
    r = mech.solve('mechanisms/fourbar.yaml', outputs='B')
    assert list(r) == r.columns == r.keys() and len(r) == len(r.columns)
    assert 'B.vx' in r and 'C.vx' not in r
    with pytest.raises(KeyError, match="did you mean 'B.vx'"):
        r['B.vxx']
    a = r.to_array()
    assert a.shape == (r.nrows, len(r.columns))
    assert_bits_equal(a[:, r.columns.index('B.x')], r['B.x'], 'to_array')
    assert 'rows' in repr(r)


def test_result_arrays_are_read_only():
    r = mech.solve('mechanisms/fourbar.yaml', outputs='B')
    assert r.nrows == 361 and all(not r[name].flags.writeable for name in r)
    before = r['B.x'].copy()
    with pytest.raises(ValueError, match='read-only'):
        r['B.x'][0] = 1.0
    with pytest.raises(ValueError, match='read-only'):
        r['B.x'] += 1.0
    assert_bits_equal(r['B.x'], before, 'B.x after the refused writes')
    # the rows of a failed solve, and a sweep's results, too
    with pytest.raises(mech.MechError) as e:
        mech.solve('tests/solve/non-grashof.yaml')
    assert not e.value.partial['q'].flags.writeable
    s = mech.sweep('mechanisms/slider-crank.yaml', {'r': ['40 mm']}, metrics=['range:B.x'], jobs=1)
    assert all(not s[name].flags.writeable for name in s)
    # to_array and copies are the caller's
    a = r.to_array()
    a[0, 0] = 1.0
    c = np.array(r['B.x'])
    c[0] = 1.0
    assert a.flags.writeable and c.flags.writeable


def test_threads_give_the_same_numbers():
    path = 'mechanisms/stirling.yaml'
    want = mech.solve(path)
    got = [None] * 4

    def work(i):
        got[i] = mech.solve(path)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in got:
        for n in want.columns:
            assert_bits_equal(r[n], want[n], n)


def test_gears_and_laws_of_time_in_the_model():
    e = mech.check('mechanisms/epicyclic.yaml')
    assert e['structure']['gears'] == 2 and e['structure']['loops'] == 0
    g = {x['name']: x for x in e['gears']}
    assert g['g_sp']['kind'] == 'pair' and g['g_sp']['links'] == ('sun', 'planet')
    assert g['g_sp']['arm'] == 'carrier' and g['g_sp']['teeth'] == (20, 40)
    assert g['g_sp']['radii'] == pytest.approx((0.020, 0.040))  # module 2 mm
    assert g['g_pr']['internal'] is True and g['g_pr']['links'] == ('planet', 'ground')
    assert g['g_pr']['pressure_angle'] == pytest.approx(math.radians(20))
    f = mech.check('mechanisms/five-bar.yaml')
    assert f['driver']['kind'] == 'time' and f['structure']['drivers'] == 2
    assert [(d['kind'], d['link'], d['law']) for d in f['drivers']] == [
        ('angle', 'crank1', '90 deg + 360 deg/s * t'),
        ('angle', 'crank2', '60 deg + 20 deg * sin(2 * pi * t / 1 s)')]
    r = mech.solve('mechanisms/five-bar.yaml')
    assert r.columns[0] == 't'
    # the driven angle follows its law (rad, t in s)
    assert r['crank1.angle'] == pytest.approx(math.radians(90) + 2 * math.pi * r['t'], abs=1e-12)


def test_simulate_equals_the_cli_and_keeps_energy():
    """mech.simulate (docs/dynamics.md): the same doubles as `mech simulate`'s
    CSV; the pendulum's energy kept; a file without a free driver refused."""
    path = 'tests/dynamics/pendulum.yaml'
    r = mech.simulate(path, to=1.0, step=0.01, rtol=1e-10, atol=1e-12)
    out = subprocess.run([MECH, 'simulate', path, '--to', '1', '--step', '0.01', '--rtol',
                          '1e-10', '--atol', '1e-12'], check=True, capture_output=True,
                         text=True).stdout.splitlines()
    names = [h[:h.index(' [')] for h in out[0].split(',')]
    assert r.columns == names
    assert r.nrows == 101 == len(out) - 1
    data = np.array([[float(x) for x in l.split(',')] for l in out[1:]])
    for i, n in enumerate(names):
        assert_bits_equal(r[n], data[:, i], n)
    assert np.max(np.abs(r['energy.balance'])) < 1e-8 * np.max(np.abs(r['energy.gravity']))
    assert r.stats['steps'] > 0 and r.stats['stop_time'] == 1.0
    with pytest.raises(mech.MechError):
        mech.simulate('mechanisms/fourbar.yaml')
    with pytest.raises(ValueError):
        mech.simulate(path, method='rk4')
    # the events: at rest half a period after release, at the vertical a quarter
    h = mech.simulate(path, stop_at_rest=True, rtol=1e-10, atol=1e-12)
    q = mech.simulate(path, stop_when='bar.angle=-90', rtol=1e-10, atol=1e-12)
    assert abs(h['t'][-1] - 2 * q['t'][-1]) < 1e-7
    assert abs(q['bar.angle'][-1] + math.pi / 2) < 1e-9


def test_read_gives_back_the_hdf5_and_the_csv_of_the_cli(tmp_path):
    """mech.read (docs/cli.md, HDF5 output): the HDF5 that `mech solve -o
    OUT.h5` writes and the CSV of the same run read back as the doubles
    mech.solve returns, bit for bit; a file that is not a table is refused."""
    path = 'mechanisms/fourbar.yaml'
    r = mech.solve(path, forces=True)
    h5, csv = str(tmp_path / 'run.h5'), str(tmp_path / 'run.csv')
    for out in (h5, csv):
        subprocess.run([MECH, 'solve', path, '--forces', '-o', out], check=True)
    for out in (h5, csv):
        t = mech.read(out)
        assert t.columns == r.columns and t.nrows == r.nrows
        for n in r.columns:
            assert_bits_equal(t[n], r[n], n)
        assert t.units == r.units
    with pytest.raises(mech.MechError):
        mech.read(path)

def fit_targets(tmp_path):
    """The worked example of docs/synthesis.md section 6: the coupler curve
    of tests/fit/fourbar.yaml (r 20, l 60, b 50 mm) at 12 crank angles, and
    the file with r 22, l 55, b 53 mm, the start."""
    out = subprocess.run([MECH, 'solve', 'tests/fit/fourbar.yaml', '--from', '0', '--to', '330',
                          '--steps', '11', '--outputs', 'P', '--level', 'positions', '--units',
                          'file'], check=True, capture_output=True, text=True).stdout
    lines = [l for l in out.splitlines() if l and not l.startswith('#')]
    path = tmp_path / 'path.csv'
    path.write_text(''.join(','.join(l.split(',')[:3]) + '\n' for l in lines))
    with open('tests/fit/fourbar.yaml') as f:
        text = f.read()
    moved = (text.replace('  r: 20 mm', '  r: 22 mm').replace('  l: 60 mm', '  l: 55 mm')
             .replace('  b: 50 mm', '  b: 53 mm'))
    assert moved != text
    return path, moved


def test_fit_recovers_the_worked_example(tmp_path):
    """mech.fit (docs/synthesis.md section 6): the dimensions back to 1e-8
    relative, from one start and from 8 bounded ones; the same as `mech fit`."""
    path, moved = fit_targets(tmp_path)
    f = tmp_path / 'moved.yaml'
    f.write_text(moved)
    r = mech.fit(f, free=['r', 'l', 'b'], target=path)
    for name, want in (('r', 0.020), ('l', 0.060), ('b', 0.050)):
        assert abs(r['params'][name] - want) <= 1e-8 * want, (name, r['params'][name])
    assert r['objective'] < 1e-20 and r['status'] == 'converged'
    assert r['starts'] == 1 and r['accepted'] == 1 and r['solves'] > 0 and r['seconds'] > 0
    assert max(r['worst_error'].values()) < 1e-12 and r['margins'] == {}
    cli = subprocess.run([MECH, 'fit', str(f), '--free', 'r,l,b', '--target', str(path)],
                         check=True, capture_output=True, text=True).stdout
    assert 'objective    %.6g ' % r['objective'] in cli
    b = mech.fit(str(f), free='r=15mm:25mm,l=50mm:70mm,b=40mm:60mm', target=str(path),
                 starts=8, jobs=2)
    assert b['starts'] == 8 and b['accepted'] == 8
    for name, want in (('r', 0.020), ('l', 0.060), ('b', 0.050)):
        assert abs(b['params'][name] - want) <= 1e-8 * want, (name, b['params'][name])


def test_fit_keeps_the_constraints(tmp_path):
    """The fit: section's constraints (docs/synthesis.md section 4): l / r >=
    3.2 excludes the answer (3); the fit ends on that boundary, at the fit of
    the file with l written 3.2 r; a bad constraint raises with its place."""
    path, moved = fit_targets(tmp_path)
    f = tmp_path / 'ratio.yaml'
    f.write_text(moved + 'fit:\n  constraints: ["l / r >= 3.2", "r + d <= l + b"]\n')
    r = mech.fit(f, free=['r', 'l', 'b'], target=path)
    p = r['params']
    assert abs(p['l'] / p['r'] - 3.2) < 1e-9
    assert abs(r['margins']['l / r >= 3.2']) < 1e-9
    assert r['margins']['r + d <= l + b'] > 0.02
    sub = tmp_path / 'sub.yaml'
    sub.write_text(re.sub(r'(?m)^  l: 55 mm.*$', '  l: 3.2 * r', moved))
    s = mech.fit(sub, free=['r', 'b'], target=path)
    assert abs(s['params']['r'] - p['r']) < 1e-11 and abs(s['params']['b'] - p['b']) < 1e-11
    bad = tmp_path / 'bad.yaml'
    bad.write_text(moved + 'fit:\n  constraints: ["l <= 3 kg"]\n')
    with pytest.raises(mech.MechError) as e:
        mech.fit(bad, free=['r', 'l', 'b'], target=path)
    assert "bad.yaml:42:20: error: fit: constraint 'l <= 3 kg': cannot subtract" in str(e.value)
    assert e.value.status == mech.EINPUT
    # the least transmission angle (53.13 deg for the answer) held at 60 deg
    plain = tmp_path / 'moved.yaml'
    plain.write_text(moved)
    t = mech.fit(plain, free=['r=15mm:25mm', 'l=50mm:70mm', 'b=40mm:60mm'], target=path,
                 starts=2, transmission=('coupler', 'rocker', 60))
    assert abs(t['margins']['transmission coupler/rocker']) < 1e-9
    never = tmp_path / 'never.yaml'
    never.write_text(moved + 'fit:\n  constraints: ["r >= 30 mm"]\n')
    with pytest.raises(mech.MechError) as e:
        mech.fit(never, free=['r=15:25', 'l', 'b'], target=path, starts=2)
    assert e.value.status == mech.ESOLVE
