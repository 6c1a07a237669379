#!/usr/bin/python3
"""How much of the plate force's deviation from its 20 ms running mean is the
flow's own (docs/pressure.md, "The decay of Eq. 23's reference step").

usage: bench/plate_force_ensemble.py DIR [--column solid_fx] [--subsets] [--plot PNG]
                                     [--rows T0 T1]

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
from check_plate_flicker import force_series_smoothness, judged_rows  # noqa: E402
from probes_csv import probes_table  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('dir')
    ap.add_argument('--column', default='solid_fx')
    ap.add_argument('--plot', metavar='PNG', help='draw one run\'s force and the mean (to 1.2 s)')
    ap.add_argument('--rows', type=float, nargs=2, metavar=('T0', 'T1'),
                    help='print the mean force\'s rows in T0-T1 s, those outside the band marked')
    ap.add_argument('--subsets', action='store_true',
                    help='the mean of the first 2, 4, 8, ... runs, and the deviation split into '
                    'what the runs share and what each has of its own')
    a = ap.parse_args()
    runs = sorted((d for d in glob.glob(os.path.join(a.dir, '*'))
                   if os.path.isfile(os.path.join(d, 'probes.csv'))),
                  key=lambda d: (0, int(os.path.basename(d)), '') if os.path.basename(d).isdigit()
                  else (1, 0, os.path.basename(d)))
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
    print('its rows outside 15%%: %s' % (', '.join(
        '%.3f-%.3f s' % iv for iv in failing_intervals(t, mean)) or 'none'))
    if a.rows:
        m, _, ok, _, _ = judged_rows(t, mean)
        bad = np.zeros(t.size, bool)
        bad[np.where(m)[0][~ok]] = True
        w = (t >= a.rows[0]) & (t <= a.rows[1])
        for tt, fx, b in zip(t[w], mean[w], bad[w]):
            print('  %.3f s  %8.1f N/m%s' % (tt, fx, '  outside' if b else ''))
        print('rows of the mean in %.3f-%.3f s: %d judged, %d outside 15%%' % (
            a.rows[0], a.rows[1], int((m & w).sum()), int((bad & w).sum())))
    if a.plot:
        plot(a.plot, t, forces, mean, a.column)
    if a.subsets:
        sizes = [n for n in (2, 4, 8, 16, 32, 64, 128) if n <= len(runs)]
        if sizes[-1] != len(runs):
            sizes.append(len(runs))
        devs = []
        for n in sizes:
            m = force_series_smoothness(t, forces[:n].mean(axis=0))
            devs.append(m['rms_dev'])
            print('mean of the first %d: within 15%% %.1f%%, RMS deviation %.2f N/m' % (
                n, 100 * m['within15'], m['rms_dev']))
        shared, independent = split_deviation(sizes, devs)
        print('RMS deviation = sqrt(shared^2 + independent^2 / N): shared %.2f N/m (the '
              'flow the runs have in common), independent %.2f N/m (each run\'s own)' % (
                  shared, independent))


def plot(path, t, forces, mean, column):
    """One realisation's force and the realisations' mean, each with its 20 ms
    running mean and the 15% band (floored at 10% of the peak as the measure
    floors it), the mean's rows outside the band marked."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
    for ax, fx, title in ((axs[0], forces[0], 'one realisation'),
                          (axs[1], mean, 'the mean of %d realisations' % len(forces))):
        _, rm, _, peak, _ = judged_rows(t, fx)
        band = 0.15 * np.maximum(np.abs(rm), 0.1 * peak)
        ax.fill_between(t, rm - band, rm + band, color='0.85', label='20 ms mean +- 15%')
        ax.plot(t, fx, lw=0.7, color='tab:blue', label='2 ms rows')
        for x0, x1 in failing_intervals(t, fx):
            ax.axvspan(x0 - 0.001, x1 + 0.001, color='tab:red', alpha=0.3, lw=0)
        ax.set_title('%s: %s (red: rows outside the band)' % (title, column))
        ax.set_ylabel('N/m')
        ax.legend(loc='upper right', fontsize=8)
    axs[1].set_xlabel('t (s)')
    axs[1].set_xlim(0, min(t[-1], 1.2))
    fig.tight_layout()
    fig.savefig(path, dpi=80)


def split_deviation(sizes, devs):
    """Least squares of dev_N^2 = shared^2 + independent^2 / N over the
    ensemble sizes N: what the runs share (their common flow's transients,
    which no number of runs averages away) and what each has of its own
    (independent between runs, so it falls as 1 / sqrt(N) in their mean).
    Negative components (noise in the fit) are returned as 0."""
    A = np.column_stack([np.ones(len(sizes)), 1.0 / np.asarray(sizes, float)])
    coef = np.linalg.lstsq(A, np.square(devs), rcond=None)[0]
    return tuple(float(np.sqrt(max(c, 0.0))) for c in coef)


def failing_intervals(t, fx, gap=0.005):
    """The time intervals of the rows outside 15% of their 20 ms mean (the
    rows force_series_smoothness judges), rows closer than gap s merged."""
    m, _, ok, _, _ = judged_rows(t, fx)
    bad = t[m][~ok]
    out = []
    for tb in bad:
        if out and tb - out[-1][1] <= gap:
            out[-1][1] = tb
        else:
            out.append([tb, tb])
    return [tuple(iv) for iv in out]


if __name__ == '__main__':
    main()
