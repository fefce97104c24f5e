"""tests/python/test_sweep.py: mech.sweep, the library's mech_sweep from
Python, against `mech sweep` (its CSV, bit for bit), exact truths (the
stroke of an in-line slider-crank is twice its crank), the shards of a grid,
random samples within the tolerances, and memory that does not grow with the
variants. Run by tests/python/run.sh (see test_mech.py)."""
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import mech
from test_mech import MECH, assert_bits_equal

SC = 'mechanisms/slider-crank.yaml'
TOL = 'tests/sweep/tol-slider-crank.yaml'


def cli_sweep(path, *args):
    """`mech sweep path args -o -` as (names, units, {name: column}): the
    status column as str, the others as float64."""
    out = subprocess.run([MECH, 'sweep', path, *args, '-q', '-o', '-'], check=True,
                         capture_output=True, text=True).stdout
    lines = [l for l in out.splitlines() if l and not l.startswith('#')]
    header = lines[0].split(',')
    names = [h[:h.index(' [')] for h in header]
    units = [h[h.index(' [') + 2:-1] for h in header]
    cells = [l.split(',') for l in lines[1:]]
    cols = {}
    for i, n in enumerate(names):
        col = [c[i] for c in cells]
        cols[n] = np.array(col) if n == 'status' else np.array([float(x) for x in col])
    return names, units, cols


def assert_same_as_cli(s, path, *args):
    names, units, cols = cli_sweep(path, *args)
    assert s.columns == names
    assert [s.units[n] for n in names] == units
    assert s.nrows == len(cols['variant'])
    for n in names:
        if n == 'status':
            assert list(s[n]) == list(cols[n])
        else:
            assert_bits_equal(s[n], cols[n], '%s %s' % (path, n))


def test_the_stroke_is_twice_the_crank():
    s = mech.sweep(SC, {'r': ['30 mm', '40 mm', '50 mm']}, metrics=['range:B.x'], jobs=3)
    assert s.columns == ['variant', 'r', 'status', 'rows', 'range:B.x']
    assert s.units['r'] == 'm' and s.units['range:B.x'] == 'm'
    assert list(s['variant']) == [0, 1, 2] and s['variant'].dtype == np.int64
    assert list(s['status']) == ['ok'] * 3 and list(s['rows']) == [73] * 3
    assert s['r'] == pytest.approx([0.03, 0.04, 0.05], abs=1e-15)
    assert s['range:B.x'] == pytest.approx(2 * s['r'], abs=1e-12)
    assert s.stats['total'] == 3 and s.stats['solved'] == 3
    assert s.stats['shared'] == 3, 'every variant through the sweep\'s one analysis'


def test_equals_the_command_line_bit_for_bit():
    metrics = ['range:B.vx', 'maxabs:B.ax', 'min:rod.angle', 'transmission:crank,rod']
    grid = {'r': '30mm:44mm:4', 'l': ['130 mm', '141mm', '15 cm']}
    s = mech.sweep(SC, grid, metrics=metrics, jobs=2)
    assert s.nrows == 12
    args = ['--vary', 'r=30mm:44mm:4', '--list', 'l=130 mm,141mm,15 cm']
    for m in metrics:
        args += ['--metric', m]
    assert_same_as_cli(s, SC, *args)
    # numbers are bare numbers of the file (mm there), as in --set
    n = mech.sweep(SC, {'l': [130, 141.5]}, metrics=['max:B.x'])
    assert n.units['l'] == '-' and list(n['l']) == [130, 141.5]
    assert n['max:B.x'] == pytest.approx([0.170, 0.1815], abs=1e-12)
    assert_same_as_cli(n, SC, '--list', 'l=130,141.5', '--metric', 'max:B.x')


def test_a_variant_that_cannot_assemble_is_a_row():
    # a crank longer than the connecting rod (140 mm) cannot turn
    s = mech.sweep(SC, {'r': ['40 mm', '150 mm']}, metrics=['max:B.x'], jobs=1)
    assert list(s['status']) == ['ok', 'no-assembly']
    assert s['rows'][1] < 73 and math.isnan(s['max:B.x'][1])
    assert list(s.messages) == [1]
    assert s.messages[1].startswith('variant 1: r=150 mm\n')
    assert 'cannot assemble' in s.messages[1]
    assert_same_as_cli(s, SC, '--list', 'r=40 mm,150 mm', '--metric', 'max:B.x', '-j', '1')


def test_shards_are_the_grid():
    grid = {'r': '30mm:40mm:5', 'l': ['135 mm', '140 mm']}
    whole = mech.sweep(SC, grid, metrics=['range:x_B.v'])
    parts = [mech.sweep(SC, grid, metrics=['range:x_B.v'], shard=(k, 3), index_offset=20)
             for k in range(3)]
    assert sum(p.nrows for p in parts) == whole.nrows == 10
    for k, p in enumerate(parts):
        assert list(p['variant']) == list(range(20 + k, 30, 3))
        rows = p['variant'] - 20
        for n in ('r', 'l', 'rows', 'range:x_B.v'):
            assert_bits_equal(p[n], whole[n][rows], 'shard %d/3 %s' % (k, n))
        assert p.stats['total'] == 10
    assert_same_as_cli(parts[1], SC, '--vary', 'r=30mm:40mm:5', '--list', 'l=135 mm,140 mm',
                       '--metric', 'range:x_B.v', '--shard', '1/3', '--index-offset', '20')


def test_random_samples_as_the_command_line():
    s = mech.sweep(TOL, random=200, seed=7, metrics=['max:B.x'])
    assert s.columns == ['variant', 'r', 'l', 'status', 'rows', 'max:B.x']
    assert (np.abs(s['r'] - 0.040) <= 0.05e-3 * (1 + 1e-12)).all()
    assert (np.abs(s['l'] - 0.120) <= 0.1e-3 * (1 + 1e-12)).all()
    assert np.ptp(s['r']) > 0.09e-3, 'the samples spread over the tolerance'
    assert_same_as_cli(s, TOL, '--random', '200', '--seed', '7', '--metric', 'max:B.x')
    other = mech.sweep(TOL, random=200, seed=8, jobs=1)
    assert (other['r'] != s['r']).all()


def test_refusals():
    with pytest.raises(mech.MechError) as e:
        mech.sweep(SC, {'r': ['40 mm']}, metrics=['range:Bx'])
    assert e.value.status == mech.EINPUT
    assert "no column 'Bx'" in str(e.value) and "did you mean 'B.x'" in str(e.value)
    assert e.value.diagnostics[0]['file'] == 'mech sweep'
    with pytest.raises(mech.MechError, match="is not a number with a unit"):
        mech.sweep(SC, {'r': ['4 parsec']})
    with pytest.raises(mech.MechError, match='nothing to vary'):
        mech.sweep(SC, {})
    with pytest.raises(mech.MechError, match='does not combine'):
        mech.sweep(TOL, {'r': ['40 mm']}, random=3)
    with pytest.raises(mech.MechError) as e:
        mech.sweep(SC, {'nosuch': ['1 mm']})
    assert e.value.status == mech.EINPUT and 'nosuch' in str(e.value)
    with pytest.raises(ValueError):
        mech.sweep(SC, {'r': ['40 mm', 'max(1 mm, 2 mm)']})
    with pytest.raises(ValueError):
        mech.sweep(SC, {'r': ['40 mm']}, shard=(3, 3))
    with pytest.raises(ValueError):
        mech.sweep(SC, {'r': ['40 mm']}, seed=-1)
    with pytest.raises(ValueError):
        mech.sweep(SC, {'r': ['40 mm']}, jobs=0)
    with pytest.raises(TypeError):
        mech.sweep(SC, {'r': [[40]]})
    s = mech.sweep(SC, {'r': ['40 mm']})
    with pytest.raises(ValueError):
        s['rows'][0] = 1  # read only


PEAK = '''
import resource, sys, mech
n = int(sys.argv[1])
s = mech.sweep('mechanisms/slider-crank.yaml', {'r': '30mm:50mm:%d' % n},
               metrics=['range:B.x'], jobs=2)
assert s.nrows == n and s.stats['solved'] == n
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
'''


@pytest.mark.skipif('LD_PRELOAD' in os.environ and 'asan' in os.environ['LD_PRELOAD'],
                    reason='AddressSanitizer keeps freed memory in quarantine: the peak RSS grows')
def test_memory_does_not_grow_with_the_variants():
    # each variant leaves its row (about 40 bytes) and nothing else: 4500
    # variants more may not cost 1 MB more at the peak (keeping each variant's
    # table, as mech.sweep did, costs about 20 KB per variant here: 90 MB)
    peak = [int(subprocess.run([sys.executable, '-c', PEAK, str(n)], check=True,
                               capture_output=True, text=True, env=os.environ).stdout)
            for n in (500, 5000)]
    assert peak[1] - peak[0] < 1024, 'peak RSS %d KB at 500 variants, %d KB at 5000' % tuple(peak)
