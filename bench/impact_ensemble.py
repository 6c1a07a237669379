#!/usr/bin/python3
"""The dam break's impact on the wall sensor as an ensemble (docs/pressure.md,
"Impact pressure on the wall, and its convergence").

usage: bench/impact_ensemble.py [--dps 0.008:16,0.004:12,0.002:6] [--jitter 0.001]
                                [--end 0.32] [--jobs 1] [--threads 1] [--out DIR]
                                [--table FILE] [--plot FILE] [--json FILE] [--set KEY=VALUE ...]

After the front hits the wall the flow is chaotic: a single run's peak pressure
is one draw, and the thread count alone (the sums' rounding) moves it by
10-25%. Experiments report impact pressures the same way for the same reason
(Lobovsky et al. 2014 repeated their dam break 100 times). So each dp is run
N times, each realisation with the fluid's starting lattice displaced by a
tiny random amount (`fluid.jitter.amplitude`, a fraction of dp, seeds 1..N),
and the quantities of the impact (pressure_quality.impact_metrics: arrival,
peak of the 2 ms rows, peak of their 10 ms running mean, time of the peak,
rise time, impulse over 50 ms) are reported as the ensemble's mean with its
standard error. Convergence is judged on those means: a successive
difference is only a difference if it is larger than its own standard
error (both means' errors combined).

--dps     dp:N pairs (N realisations at that dp);
--jitter  the starting displacement, a fraction of dp (default 1e-3: far
          below anything the flow before the impact feels, the arrival is
          the same row);
--end     end_time of each run (the impulse's 50 ms window after the
          arrival at about 0.26 s must fit);
--jobs    runs at once; --threads their OMP_NUM_THREADS (the realisations
          are seeds, so one thread count for all);
--reuse   keep the runs already in OUT (their summary.json says ok).
"""
import argparse, concurrent.futures, json, math, os, sys, tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from pressure_quality import impact_metrics, probes, run  # noqa: E402  (one definition)

KEYS = (('t_arrive', 'arrival (s)', 1.0, '%.4f'),
        ('peak', 'peak of the 2 ms rows (Pa)', 1.0, '%.0f'),
        ('peak_10ms', 'peak of the 10 ms mean (Pa)', 1.0, '%.0f'),
        ('t_peak', 'time of the peak (s)', 1.0, '%.4f'),
        ('rise', 'rise to 90% (ms)', 1000.0, '%.1f'),
        ('impulse', 'impulse over 50 ms (Pa s)', 1.0, '%.1f'))


def one_run(a, dp, seed):
    out = os.path.join(a.out, 'db_%s_s%d' % (dp, seed))
    summ = os.path.join(out, 'summary.json')
    if a.reuse and os.path.exists(summ):
        with open(summ) as f:
            if json.load(f).get('status') == 'ok':
                return out
    run(os.path.join(a.build, 'bin', 'fluid_solver'), 'cases/dambreak/case.yml', out,
        ['dp=%s' % dp, 'end_time=%g' % a.end, 'output.interval=0', 'fluid.jitter.amplitude=%g' % a.jitter,
         'fluid.jitter.seed=%d' % seed] + a.set, env={'OMP_NUM_THREADS': str(a.threads)})
    return out


def signals(runs, dp, n):
    """The n realisations' p_wall rows side by side (rows k of all runs are
    the first steps past the same probe time) and their mean times."""
    sig = [probes(runs[(dp, s)]) for s in range(1, n + 1)]
    k = min(len(p['time']) for p in sig)
    return (np.mean([p['time'][:k] for p in sig], axis=0),
            np.array([p['p_wall'][:k] for p in sig]))


def stats(vals):
    v = np.array([x for x in vals if np.isfinite(x)])
    if len(v) < 2:
        return float(v.mean()) if len(v) else float('nan'), float('nan'), float('nan')
    sd = float(v.std(ddof=1))
    return float(v.mean()), sd, sd / math.sqrt(len(v))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    ap.add_argument('--dps', default='0.008:16,0.004:12,0.002:6')
    ap.add_argument('--jitter', type=float, default=1e-3)
    ap.add_argument('--end', type=float, default=0.32)
    ap.add_argument('--jobs', type=int, default=1)
    ap.add_argument('--threads', type=int, default=1)
    ap.add_argument('--out', default=None)
    ap.add_argument('--table', default=None)
    ap.add_argument('--plot', default=None)
    ap.add_argument('--json', default=None, help='every run\'s metrics and the ensembles\' means')
    ap.add_argument('--reuse', action='store_true')
    ap.add_argument('--set', action='append', default=[], metavar='KEY=VALUE')
    a = ap.parse_args()
    a.out = a.out or tempfile.mkdtemp(prefix='impact_ensemble_')
    os.makedirs(a.out, exist_ok=True)
    plan = []
    for item in a.dps.split(','):
        dp, n = item.split(':') if ':' in item else (item, '8')
        plan.append((dp, int(n)))

    runs = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        futs = {(dp, s): pool.submit(one_run, a, dp, s) for dp, n in plan for s in range(1, n + 1)}
        for key, fut in futs.items():
            runs[key] = fut.result()

    lines = ['Dam break (cases/dambreak), sensor p_wall: ensemble of N realisations per dp '
             '(`fluid.jitter.amplitude=%g`, seeds 1..N, %d thread(s), to %g s%s). '
             'Each entry: mean +- standard error (standard deviation).' % (
                 a.jitter, a.threads, a.end, ''.join(', --set ' + s for s in a.set)), '',
             '| dp (mm) | N | ' + ' | '.join(k[1] for k in KEYS) + ' | steps | wall s per run |',
             '|---|---|' + '---|' * len(KEYS) + '---|---|']
    means, record = {}, {'jitter': a.jitter, 'threads': a.threads, 'end': a.end, 'sets': a.set, 'dps': {}}
    for dp, n in plan:
        ms, steps, wall = [], [], []
        for s in range(1, n + 1):
            out = runs[(dp, s)]
            ms.append(impact_metrics(out))
            with open(os.path.join(out, 'summary.json')) as f:
                summ = json.load(f)
            steps.append(summ['steps'])
            wall.append(summ['wall_seconds'])
        cells = []
        for key, _, scale, fmt in KEYS:
            m, sd, se = stats([scale * x[key] for x in ms if x])
            means[(dp, key)] = (m, se)
            record['dps'].setdefault(dp, {'runs': [runs[(dp, s)] for s in range(1, n + 1)],
                                          'metrics': ms})[key] = {'mean': m, 'sd': sd, 'se': se}
            cells.append((fmt + ' +- ' + fmt + ' (' + fmt + ')') % (m, se, sd))
        lines.append('| %g | %d | %s | %.0f | %.1f |' % (1000 * float(dp), n, ' | '.join(cells),
                                                         np.mean(steps), np.mean(wall)))
    lines.append('')
    dps = [dp for dp, _ in plan]
    for key, name, _, fmt in KEYS:
        parts = []
        for j in range(len(dps) - 1):
            (m1, e1), (m2, e2) = means[(dps[j], key)], means[(dps[j + 1], key)]
            parts.append((fmt + ' +- ' + fmt) % (m1 - m2, math.hypot(e1, e2)))
        text = '%s: successive differences %s' % (name, ', '.join(parts))
        orders = []
        for j in range(len(dps) - 2):
            q = [means[(dp, key)][0] for dp in dps[j:j + 3]]
            d1, d2 = q[0] - q[1], q[1] - q[2]
            orders.append('%.2f' % math.log2(abs(d1) / abs(d2)) if d1 and d2 and (d1 > 0) == (d2 > 0)
                          else 'none (the sign changes)')
        if orders:
            text += ': observed order %s' % ', '.join(orders)
        lines.append(text + '  ')
    # The peak of the ensemble's mean signal: the mean of the peaks above is
    # biased up by each run's noise (the largest of noisy rows); the mean
    # signal averages the noise first. Its standard error by a bootstrap
    # over the realisations (a fixed generator: the table is reproducible).
    lines += ['', '| dp (mm) | peak of the ensemble-mean signal, 2 ms rows (Pa) | at (s) |', '|---|---|---|']
    rng = np.random.default_rng(12345)
    peaks_of_mean = []
    for dp, n in plan:
        t, v = signals(runs, dp, n)
        j = int(np.argmax(v.mean(axis=0)))
        boot = [v[rng.integers(0, n, n)].mean(axis=0).max() for _ in range(400)]
        peaks_of_mean.append(float(v.mean(axis=0)[j]))
        record['dps'][dp]['peak_of_mean'] = {'value': peaks_of_mean[-1], 'se': float(np.std(boot)),
                                            'time': float(t[j])}
        lines.append('| %g | %.0f +- %.0f | %.4f |' % (1000 * float(dp), peaks_of_mean[-1], np.std(boot), t[j]))
    if len(plan) >= 2:
        lines += ['', 'peak of the ensemble-mean signal: successive differences %s' % ', '.join(
            '%.0f' % (peaks_of_mean[j] - peaks_of_mean[j + 1]) for j in range(len(plan) - 1))]
    table = '\n'.join(lines) + '\n'
    print(table)
    if a.table:
        with open(a.table, 'w') as f:
            f.write(table)
    if a.json:
        with open(a.json, 'w') as f:
            json.dump(record, f, indent=1)

    if a.plot:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4))
        for dp, n in plan:
            t, v = signals(runs, dp, n)
            line, = ax.plot(t, v.mean(axis=0), lw=1.0, label='dp = %g mm (mean of %d)' % (1000 * float(dp), n))
            ax.fill_between(t, v.mean(axis=0) - v.std(axis=0), v.mean(axis=0) + v.std(axis=0),
                            color=line.get_color(), alpha=0.2, lw=0)
        ax.set_xlim(0.24, a.end)
        ax.set_xlabel('t (s)')
        ax.set_ylabel('p_wall, 2 ms rows (Pa)')
        ax.set_title('ensemble mean and +- one standard deviation')
        ax.legend()
        fig.tight_layout()
        fig.savefig(a.plot, dpi=90)


if __name__ == '__main__':
    main()
