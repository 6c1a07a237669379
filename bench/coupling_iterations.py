#!/usr/bin/python3
"""How hard the implicit coupling works in a run (docs/sloshing.md, "The
coupling stiffens below 1 mm").

usage: bench/coupling_iterations.py RUN [RUN ...] [--window T0 T1 ...]

Reads RUN/iterations.csv (written with --set coupling.implicit.log=true) and
prints one markdown row per run and window [T0, T1) of simulated time:
  - fluid advances per coupling step (iterations per step);
  - the first iterate's miss: its interface change over the step's
    displacement (median), and the share of steps that pass there (the test
    is change <= tolerance x displacement, tolerance 0.1 by default);
  - the Aitken factor (median of the factors the steps used, 0 rows left out;
    meaningless for iqn_ils);
  - how much one more iteration shrinks the change (median of change at the
    second iterate over change at the first, over the steps that repeat):
    about 1 - factor (1 + lambda) for a map whose feedback is -lambda.
Windows default to 0-0.3 and 0.3-0.6 s.

--probes: from RUN/probes.csv instead (no iteration log needed), the mean of
its coupling_iterations column (fluid advances per step, each row the mean
over its probe interval) over each window (T0, T1].

--gain W: RUN is one coupling step run with a constant factor W and a
tolerance too tight to stop (docs/sloshing.md, "Why 0.8 and 0.5 mm"); prints
the ratios of successive changes (the last row, the best iterate restored at
the limit, left out) and the gain the largest ratio implies, (ratio + 1) / W - 1
for a growing mode. A ratio near 1 - W means no feedback is seen."""
import argparse, csv, os, sys

import numpy as np


def read(run):
    path = os.path.join(run, 'iterations.csv')
    try:
        with open(path, newline='') as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f'coupling_iterations: {path}: {e.strerror} (run with --set '
                 'coupling.implicit.log=true)')
    steps = {}
    for r in rows:
        try:
            step, it = int(r['step']), int(r['iteration'])
            vals = (float(r['time']), float(r['change_rms_m']),
                    float(r['step_displacement_rms_m']), float(r['factor']))
        except (KeyError, TypeError, ValueError):
            continue  # a row cut short by a run still going
        steps.setdefault(step, []).append((it,) + vals)
    return steps


def window_row(steps, t0, t1, tol):
    sel = [v for v in steps.values() if t0 <= v[0][1] < t1]
    if not sel:
        return None
    adv = np.mean([len(v) for v in sel])
    miss = np.array([v[0][2] / v[0][3] for v in sel if v[0][3] > 0])
    factors = [r[4] for v in sel for r in v if r[4] > 0]
    shrink = [v[1][2] / v[0][2] for v in sel if len(v) > 1 and v[0][2] > 0]
    return (len(sel), adv, np.median(miss), np.mean(miss <= tol),
            np.median(factors) if factors else float('nan'),
            np.median(shrink) if shrink else float('nan'))


def gain(runs, w):
    for run in runs:
        steps = read(run)
        if 0 not in steps:
            sys.exit(f'coupling_iterations: {run}/iterations.csv: no first step')
        change = [r[2] for r in sorted(steps[0])][:-1]
        ratios = [b / c for c, b in zip(change, change[1:]) if c > 0]
        # the largest ratio: once the mode is large the fluid's answer
        # saturates (a particle at P = 0) and the ratio falls again
        top = max(ratios) if ratios else float('nan')
        lam = (top + 1.0) / w - 1.0 if top > abs(1.0 - w) + 0.05 else None
        print(f'{run}: ratios {" ".join(f"{q:.2f}" for q in ratios)}; '
              + (f'gain about {lam:.1f}' if lam is not None else 'no growing mode seen'))


def from_probes(runs, edges):
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from probes_csv import probes_table
    print('| run | ' + ' | '.join(f'{t0:g}-{t1:g} s' for t0, t1 in zip(edges, edges[1:])) + ' |')
    print('|---|' + '---|' * (len(edges) - 1))
    for run in runs:
        try:
            p = probes_table(os.path.join(run, 'probes.csv'))
        except OSError as e:
            sys.exit(f'coupling_iterations: {run}/probes.csv: {e.strerror}')
        if 'coupling_iterations' not in (p.dtype.names or ()):
            sys.exit(f'coupling_iterations: {run}/probes.csv: no coupling_iterations column '
                     '(an explicit run?)')
        cells = []
        for t0, t1 in zip(edges, edges[1:]):
            sel = (p['time'] > t0) & (p['time'] <= t1)
            cells.append(f'{np.mean(p["coupling_iterations"][sel]):.2f}' if sel.any() else '')
        print(f'| {run} | ' + ' | '.join(cells) + ' |')


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--window', nargs='+', type=float, default=[0.0, 0.3, 0.6],
                    help='window edges, s (default 0 0.3 0.6)')
    ap.add_argument('--tolerance', type=float, default=0.1,
                    help='the case\'s coupling.implicit.tolerance (default 0.1)')
    ap.add_argument('--probes', action='store_true',
                    help='advances per step from probes.csv (coupling_iterations)')
    ap.add_argument('--gain', type=float, metavar='W',
                    help='one first step at constant factor W: change ratios and the gain')
    a = ap.parse_args()
    if a.gain is not None:
        return gain(a.runs, a.gain)
    if a.probes:
        return from_probes(a.runs, a.window)
    if len(a.window) < 2 or any(b <= c for c, b in zip(a.window, a.window[1:])):
        sys.exit('coupling_iterations: --window needs two or more increasing times')
    runs = [(run, read(run)) for run in a.runs]
    print('| run | window (s) | steps | fluid advances per step | first iterate\'s miss '
          '(median) | steps passing at the first | Aitken factor (median) | change kept '
          'by one more iteration (median) |')
    print('|---|---|---|---|---|---|---|---|')
    for run, steps in runs:
        for t0, t1 in zip(a.window, a.window[1:]):
            r = window_row(steps, t0, t1, a.tolerance)
            if r is None:
                print(f'| {run} | {t0:g}-{t1:g} | 0 | | | | | |')
                continue
            n, adv, miss, passing, factor, shrink = r
            print(f'| {run} | {t0:g}-{t1:g} | {n} | {adv:.2f} | {miss:.3f} | {100 * passing:.0f}% '
                  f'| {factor:.3f} | {shrink:.2f} |')


if __name__ == '__main__':
    main()
