#!/usr/bin/python3
"""How much of the plate force's deviation from its 20 ms running mean is the
flow's own (docs/pressure.md, "The decay of Eq. 23's reference step").

usage: bench/plate_force_ensemble.py DIR [--column solid_fx]

DIR: the realisations of bench/flicker_ensemble.py --plate (DIR/1, DIR/2, ...).
Prints the share of the 2 ms force rows within 15% of their 20 ms running mean
and the RMS of the deviation (tests/coupler/check_plate_flicker.py) for each
realisation, their mean, and the same for the mean force of the realisations
(each interpolated to the first one's row times: a row is written at the
first step that reaches its time), with that mean force's largest and
smallest row.
That mean keeps what the realisations share (the impacts, the flow's own
transients a 20 ms mean cannot follow) and averages away most of their
independent noise, so its share is about what a run without noise could reach."""
import argparse, glob, os, sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(HERE), 'tests', 'coupler'))
from check_plate_flicker import force_series_smoothness  # noqa: E402
from probes_csv import probes_table  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('dir')
    ap.add_argument('--column', default='solid_fx')
    a = ap.parse_args()
    runs = sorted((d for d in glob.glob(os.path.join(a.dir, '*'))
                   if os.path.isfile(os.path.join(d, 'probes.csv'))), key=os.path.basename)
    if len(runs) < 2:
        sys.exit('plate_force_ensemble: fewer than two runs with probes.csv in %s' % a.dir)
    tables = [probes_table(os.path.join(r, 'probes.csv')) for r in runs]
    t = tables[0]['time']
    t = t[t <= min(p['time'][-1] for p in tables)]
    each = [force_series_smoothness(p['time'], p[a.column]) for p in tables]
    forces = np.array([np.interp(t, p['time'], p[a.column]) for p in tables])
    for r, m in zip(runs, each):
        print('%s: within 15%% %.1f%%, RMS deviation %.2f N/m' % (r, 100 * m['within15'], m['rms_dev']))
    print('each run: within 15%% %.1f%% (mean), RMS deviation %.2f N/m' % (
        100 * np.mean([m['within15'] for m in each]), np.mean([m['rms_dev'] for m in each])))
    mean = forces.mean(axis=0)
    em = force_series_smoothness(t, mean)
    print('mean force of the %d runs: within 15%% %.1f%%, RMS deviation %.2f N/m; largest '
          '%.0f N/m at %.3f s, smallest %.0f N/m at %.3f s' % (
              len(runs), 100 * em['within15'], em['rms_dev'], mean.max(), t[mean.argmax()],
              mean.min(), t[mean.argmin()]))


if __name__ == '__main__':
    main()
