#!/usr/bin/python3
"""The plate at rest's drift (issue 18, docs/hard_cases.md section 4), with how
well one run can know it.

usage: bench/rest_drift.py RUN [RUN...] [--fe M] [--ref M] [--block S] [--fit-end T]
                           [--fit-start T] [--per S]

The issue's drift is the mean tip_dx over 4-5 s minus the mean over 1-2 s.
The plate rings with the water about its mean (the water's seiches and the
fluid's step-to-step noise, a few tenths of a millimetre), and two one-second
means of such a signal differ by chance. So this also fits a straight line to
the means of blocks of --block s (0.5 s: longer than the plate's period in
water and the left basin's first seiche, 0.77 s, is not) over 1-5 s and
gives its slope over the 4 s with the standard error of that slope from the
blocks' scatter about the line (blocks taken as independent). A drift is
resolved only where it exceeds about twice its standard error.
--fe: the static deflection the mean over 4-5 s is compared with, m (default:
the converged FE's at 3 mm with each closed basin holding its water, 5.587 mm,
bench/plate_fe_reference.json "follower_fixed_volume"; until 2026-12-03 the
FE at the fixed levels, 5.7275 mm, which `--fe 0.0057275` gives);
--ref: the one the drift is relative to (default: the same FE, as
hard_cases.md's table since 2026-12-03; the beam theory's 5.6278 mm before)."""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tests', 'coupler'))
from hard_check import read_probes  # noqa: E402


def fixed_volume_fe(dp=0.003):
    """The converged FE tip (m) with the closed basins' volumes held."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'plate_fe_reference.json')
    return json.load(open(path))['dp'][repr(dp)]['follower_fixed_volume'][0]


FE_FIXED_VOLUME_3MM = fixed_volume_fe()


def drift(t, x, block=0.5, t0=1.0, t1=5.0):
    """(mean 4-5 s, mean 4-5 s - mean 1-2 s, slope fit over [t0, t1] times
    (t1 - t0), its standard error, the blocks' residual standard deviation),
    all in x's unit."""
    m12 = x[(t >= 1) & (t <= 2)].mean()
    m45 = x[(t >= 4) & (t <= 5)].mean()
    edges = np.arange(t0, t1 + 1e-9, block)
    tc, xb = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        m = (t >= a) & (t < b)
        if m.any():
            tc.append(0.5 * (a + b))
            xb.append(x[m].mean())
    tc, xb = np.array(tc), np.array(xb)
    if len(tc) < 3:
        return m45, m45 - m12, float('nan'), float('nan'), float('nan')
    A = np.vstack([np.ones_like(tc), tc - tc.mean()]).T
    c, *_ = np.linalg.lstsq(A, xb, rcond=None)
    r = xb - A @ c
    s = np.sqrt(np.sum(r ** 2) / (len(tc) - 2))
    se = s / np.sqrt(np.sum((tc - tc.mean()) ** 2))
    return m45, m45 - m12, c[1] * (t1 - t0), se * (t1 - t0), s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--fe', type=float, default=FE_FIXED_VOLUME_3MM)
    ap.add_argument('--ref', type=float, default=None, help='default: --fe')
    ap.add_argument('--block', type=float, default=0.5)
    ap.add_argument('--fit-end', type=float, default=5.0,
                    help='end of the fit window, s (a longer run narrows the slope: its '
                         'drift is then given per --per s)')
    ap.add_argument('--fit-start', type=float, default=1.0,
                    help='start of the fit window, s (2: after the release has settled)')
    ap.add_argument('--per', type=float, default=4.0,
                    help='the fitted drift per this many seconds (4: as over 1-5 s)')
    a = ap.parse_args()
    a.ref = a.ref or a.fe
    for run in a.runs:
        d = read_probes(run)
        t, x = d['time'], d['tip_dx']
        if t[-1] < max(5.0, a.fit_end) - 1e-6:
            print(f'{run}: reached {t[-1]:.3f} s, not {max(5.0, a.fit_end):g} s: no drift')
            continue
        m45, d45, fit, se, s = drift(t, x, a.block, t0=a.fit_start, t1=a.fit_end)
        span = a.fit_end - a.fit_start
        fit, se = fit * a.per / span, se * a.per / span
        print(f'{run}: mean 4-5 s {1e3 * m45:.3f} mm ({100 * (m45 / a.fe - 1):+.1f}% of '
              f'{1e3 * a.fe:.3f}); drift 1-2 -> 4-5 s {100 * d45 / a.ref:+.2f}%; '
              f'fit over {a.fit_start:g}-{a.fit_end:g} s, per {a.per:g} s: {100 * fit / a.ref:+.2f}% '
              f'+- {100 * se / a.ref:.2f}% ({a.block:g} s blocks scatter {1e3 * s:.3f} mm)')
        if 'p_left' in d.dtype.names:
            # the water's level: the left basin's bottom pressure (rho g h' with h' the
            # level its closed volume holds: 569.7 Pa at 3 mm, docs/hard_cases.md)
            p = d['p_left']
            last = np.floor(t[-1] + 1e-9)
            print(f'{run}: left bottom pressure {p[(t >= 1) & (t <= 2)].mean():.1f} Pa over 1-2 s, '
                  f'{p[(t >= last - 1) & (t <= last)].mean():.1f} Pa over {last - 1:g}-{last:g} s')


if __name__ == '__main__':
    main()
