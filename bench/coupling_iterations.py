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
Windows default to 0-0.3 and 0.3-0.6 s."""
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--window', nargs='+', type=float, default=[0.0, 0.3, 0.6],
                    help='window edges, s (default 0 0.3 0.6)')
    ap.add_argument('--tolerance', type=float, default=0.1,
                    help='the case\'s coupling.implicit.tolerance (default 0.1)')
    a = ap.parse_args()
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
