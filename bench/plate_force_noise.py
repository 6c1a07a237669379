#!/usr/bin/python3
"""Where the dam-break plate's force noise is (docs/pressure.md, "The 3 mm
plate's force noise: where it is").

usage: bench/plate_force_noise.py RUN [RUN ...] [--after 0.7] [--before 1.25]
                                  [--snapshots] [--dp DP] [--column solid_fx]
                                  [--split T] [--spectrum]

For each RUN (a coupled run of cases/dambreak_elastic_plate):
- the issue's measure (tests/coupler/check_plate_flicker.py): the share of
  the 2 ms force rows within 15% of their 20 ms running mean, split into the
  rows where that mean is at least 10% of the peak ("loaded") and the rest
  ("quiet"), where the band is the floor's absolute 1.5% of the peak. Needs
  probes every 2 ms (the case's output.probe_interval). --column names the
  force (default solid_fx, the solid's; plate_force_x is the fluid's, which
  a rigid plate held by the fake solid also has). --split T also splits the
  measure at time T, and with several runs prints the mean +- standard error
  over them of the measure and of its two parts, and the mean RMS deviation
  and force peak. --spectrum prints, for the
  first run, the RMS of the 2 ms rows' deviation from their 20 ms mean in
  each 0.1 s from 0.1 s, and over all runs the power spectrum of that
  deviation over 0.12-0.63 s (256 rows of the case's 2 ms, Hann window) in
  8 Hz bands;
- with probes finer than the fluid's step (output.probe_interval=2.5e-4: a
  probe row then holds one coupling step's load), the RMS of the step loads'
  deviation from their running mean over about 20 ms, and its lag-1
  autocorrelation (about -0.3 for a step-to-step alternation, near 1 for a
  smooth signal), over --after to --before s; the same for each probe
  column whose name starts with wall_ (fluid probes of kind wall_force);
- --snapshots (output.interval below the fluid's step, e.g. 5e-4): from the
  solid snapshots, the step-to-step change of the x-load on each face of the
  plate and the correlation of the two faces' changes (near -1: the
  pressure on both faces rises and falls together, and the net force is
  what of it does not cancel), the share of the faces' particles (below
  y = 0.06 m) at exactly zero load and the fast part of their velocity;
  from the fluid snapshots, the RMS step
  change of the pressure and of the x-velocity of fluid particles within 1.6 dp of the plate and
  of the tank's right wall, below y = 0.06 m.
The plate's faces are the columns of the smallest and largest starting x
(position - displacement) of the solid particles."""
import argparse
import glob
import os
import sys

import h5py
import numpy as np
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'tests', 'coupler'))
from check_plate_flicker import force_series_smoothness, probes_table, running_mean  # noqa: E402

WINDOW = 0.02  # s: the running mean
TANK_RIGHT = 0.584  # m: the case's tank width


def split_within15(t, fx, split=None):
    """The issue's measure (check_plate_flicker.force_series_smoothness)
    split by the running mean's size: (all, loaded, quiet, share of quiet
    rows), the quiet rows' RMS deviation from the mean (N/m) and the whole
    result (with the split in time, if asked), or None for probes finer than
    1.5 ms."""
    if np.median(np.diff(t)) < 1.5e-3:
        return None
    r = force_series_smoothness(t, fx, split)
    return (r['within15'], r['within15_loaded'], r['within15_quiet'], r['quiet_share']), \
        r['quiet_rms_dev'], r


def deviation(t, fx):
    """The rows' deviation from their centred 20 ms running mean."""
    return fx - running_mean(t, fx)


def deviation_spectrum(series):
    """The summed power spectrum of deviation() over 0.12-0.63 s of each
    (t, fx) series, normalised to 1, and its frequencies (Hz)."""
    n, spec = 256, 0.0
    for t, fx in series:
        d = deviation(t, fx)[(t >= 0.12) & (t < 0.632)][:n]
        spec = spec + np.abs(np.fft.rfft(d * np.hanning(n))) ** 2
    return np.fft.rfftfreq(n, 0.002), spec / spec.sum()


def step_noise(t, fx, probe_interval, after, before):
    """RMS of the step loads about their ~20 ms running mean, lag-1
    autocorrelation; None unless probes are at most 0.5 ms apart (then,
    shorter than the fluid's step, each row holds one step's load)."""
    if probe_interval > 5e-4:
        return None
    w = 2 * int(round(WINDOW / np.median(np.diff(t[(t > after) & (t < before)])) / 2)) + 1
    dev = fx - np.convolve(fx, np.ones(w) / w, mode='same')
    x = dev[(t > after) & (t < before)]
    return float(x.std()), float(np.corrcoef(x[:-1], x[1:])[0, 1])


def snapshot_series(run, kind, after, before):
    out = []
    for fn in sorted(glob.glob(os.path.join(run, f'{kind}_*.h5'))):
        with h5py.File(fn, 'r') as f:
            t = float(f.attrs['time'])
            if after <= t <= before:
                out.append((t, fn))
    # a snapshot whose time repeats (two outputs inside one step) is one step
    seen, uniq = set(), []
    for t, fn in out:
        if t not in seen:
            seen.add(t)
            uniq.append((t, fn))
    return uniq


def face_loads(run, after, before):
    """Over the plate's two faces: the step changes of each face's x-load
    (N/m; RMS left, RMS right, their correlation, the RMS step change of the
    net load), the share of the faces' particles below y = 0.06 m whose load
    is exactly zero, and the fast part of their x-velocity (m/s RMS, a 9-step
    running mean removed: the solid's particle-scale motion)."""
    left, right, zero, vel = [], [], [], []
    for _, fn in snapshot_series(run, 'solid', after, before):
        with h5py.File(fn, 'r') as f:
            pos = f['particles/position'][:][:, :2]
            x0 = np.round(pos - f['particles/displacement'][:][:, :2], 7)
            ax = f['particles/load_acceleration'][:][:, :2]
            vx = f['particles/velocity'][:][:, 0]
            case = yaml.safe_load(f['config'][()].decode())
        cols = np.unique(x0[:, 0])
        # a particle's mass per metre: the body's density times its area,
        # the solid's spacing squared (dp / solid.refine)
        dps = case['dp'] / case['solid'].get('refine', 1)
        mass = case['solid']['bodies'][0]['rho'] * dps * dps
        faces = (x0[:, 0] == cols[0]) | (x0[:, 0] == cols[-1])
        low = faces & (x0[:, 1] < 0.06)
        left.append(mass * ax[x0[:, 0] == cols[0], 0].sum())
        right.append(mass * ax[x0[:, 0] == cols[-1], 0].sum())
        zero.append(np.mean(np.hypot(ax[low, 0], ax[low, 1]) == 0.0))
        vel.append(vx[low])
    if len(left) < 20:
        return None
    dl, dr = np.diff(left), np.diff(right)
    v = np.array(vel)
    k = 9
    smooth = np.apply_along_axis(lambda a: np.convolve(a, np.ones(k) / k, mode='same'), 0, v)
    return float(dl.std()), float(dr.std()), float(np.corrcoef(dl, dr)[0, 1]), \
        float(np.diff(np.add(left, right)).std()), float(np.mean(zero)), \
        float((v - smooth)[k:-k].std())


def near_pressure(run, dp, after, before):
    """RMS step change of the pressure (Pa) and of the x-velocity (m/s) of
    the fluid particles within 1.6 dp of the plate and of the right wall,
    below y = 0.06 m, following each particle by its id: {region: (Pa, m/s)}."""
    from scipy.spatial import cKDTree
    solids = dict(snapshot_series(run, 'solid', after, before))
    prev, acc = None, {'plate': [], 'right wall': []}
    for t, fn in snapshot_series(run, 'fluid', after, before):
        if t not in solids:
            continue
        with h5py.File(fn, 'r') as f:
            fluid = f['particles/type'][:] == 0
            x = f['particles/position'][:][:, :2]
            p = f['particles/pressure'][:]
            vx = f['particles/velocity'][:][:, 0]
            ids = f['particles/id'][:]
        with h5py.File(solids[t], 'r') as g:
            xs = g['particles/position'][:][:, :2]
        dist, _ = cKDTree(xs).query(x)
        low = fluid & (x[:, 1] < 0.06)
        cur = {}
        for name, sel in (('plate', low & (dist < 1.6 * dp)),
                          ('right wall', low & (x[:, 0] > TANK_RIGHT - 1.6 * dp))):
            cur.update({(name, i): (a, b) for i, a, b in zip(ids[sel], p[sel], vx[sel])})
        if prev is not None:
            for k, v in cur.items():
                if k in prev:
                    acc[k[0]].append((v[0] - prev[k][0], v[1] - prev[k][1]))
        prev = cur
    return {k: tuple(np.sqrt(np.mean(np.square(v), axis=0))) if v else (float('nan'),) * 2
            for k, v in acc.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--after', type=float, default=0.7)
    ap.add_argument('--before', type=float, default=1.25)
    ap.add_argument('--snapshots', action='store_true')
    ap.add_argument('--dp', type=float, default=None, help='the fluid spacing (for --snapshots)')
    ap.add_argument('--column', default='solid_fx', help='the force column (default solid_fx)')
    ap.add_argument('--split', type=float, default=None, metavar='T',
                    help='also the measure before and from T s')
    ap.add_argument('--spectrum', action='store_true',
                    help='the deviation per 0.1 s (first run) and its spectrum (all runs)')
    a = ap.parse_args()
    status = 0
    splits, series = [], []
    for run in a.runs:
        path = os.path.join(run, 'probes.csv')
        if not os.path.exists(path):
            print(f'{run}: no probes.csv', file=sys.stderr)
            status = 1
            continue
        p = probes_table(path)
        if a.column not in p.dtype.names:
            print(f'{run}: probes.csv has no column {a.column}', file=sys.stderr)
            status = 1
            continue
        t, fx = p['time'], p[a.column]
        series.append((t, fx))
        parts = [run]
        s = split_within15(t, fx, a.split)
        if s:
            parts.append('2 ms rows within 15%%: %.1f%% (loaded %.1f%%, quiet %.1f%%; quiet rows %.0f%%)'
                         % tuple(100 * v for v in s[0]) + ', quiet rows off their mean by %.2f N/m RMS'
                         % s[1])
            if a.split is not None:
                r = s[2]
                splits.append((100 * r['within15'], 100 * r['within15_before'],
                               100 * r['within15_after'], r['rms_dev'], r['peak']))
                parts.append('before %g s %.1f%%, from it %.1f%%'
                             % (a.split, 100 * r['within15_before'], 100 * r['within15_after']))
        with open(os.path.join(run, 'case_resolved.yml')) as f:
            case = yaml.safe_load(f)
        pi = float(case['output']['probe_interval'])
        n = step_noise(t, fx, pi, a.after, a.before)
        if n:
            parts.append('step loads %.2f N/m RMS about the 20 ms mean, lag-1 %+.2f' % n)
        for col in p.dtype.names:
            n = step_noise(t, p[col], pi, a.after, a.before) if col.startswith('wall_') else None
            if n:
                parts.append('%s %.2f N/m, lag-1 %+.2f' % ((col,) + n))
        if a.snapshots:
            if a.dp is None:
                ap.error('--snapshots needs --dp')
            f = face_loads(run, a.after, a.before)
            if f:
                parts.append('faces step change %.1f / %.1f N/m, correlation %+.2f, net %.1f N/m; '
                             'faces\' particles at zero load %.1f%%; their fast x-velocity %.4f m/s'
                             % (f[:4] + (100 * f[4], f[5])))
            q = near_pressure(run, a.dp, a.after, a.before)
            parts.append('step change next to the plate %.0f Pa and %.4f m/s, the right wall '
                         '%.0f Pa and %.4f m/s' % (q['plate'] + q['right wall']))
        print(' | '.join(parts))
    if len(splits) > 1:
        v = np.array(splits)
        mean, se = v.mean(0), v.std(0, ddof=1) / np.sqrt(len(v))
        print('%d runs, rows within 15%%: all %.1f +- %.1f%%, before %g s %.1f +- %.1f%%, '
              'from it %.1f +- %.1f%%; RMS deviation %.1f N/m, peak %.0f N/m (means)'
              % (len(v), mean[0], se[0], a.split, mean[1], se[1], mean[2], se[2], mean[3],
                 mean[4]))
    if a.spectrum and series:
        t, fx = series[0]
        d = deviation(t, fx)
        print('deviation per 0.1 s from 0.1 s, N/m RMS: ' + ' '.join(
            '%.1f' % np.sqrt(np.mean(d[(t >= b) & (t < b + 0.1)] ** 2))
            for b in np.arange(0.1, t[-1] - 0.05, 0.1)))
        f, pw = deviation_spectrum(series)
        print('its spectrum, 0.12-0.63 s, %d runs: ' % len(series) + ' '.join(
            '%.0f-%.0f Hz %.0f%%' % (f[i], f[i + 3], 100 * pw[i:i + 4].sum())
            for i in range(0, len(f) - 3, 4)))
    return status


if __name__ == '__main__':
    sys.exit(main())
