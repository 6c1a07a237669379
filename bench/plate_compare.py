#!/usr/bin/python3
"""Compare a coupled dam-break-on-a-plate run with the published curves.

usage: plate_compare.py RUN_DIR [RUN_DIR...] [--tmax 1.0] [--plot FILE.png]
           [--peak-band LO HI] [--peak-time TLO THI] [--max-after T LIM] [--json]
For each run: the first peak of tip_dx (the maximum before t = 0.4 s) and its
time, the RMS and max difference from Walhorn et al.'s FEM curve over
[0, tmax], and whether the peak lies in the band. Reference:
cases/dambreak_elastic_plate/walhorn2005.csv (eleven numerical methods).
--max-after T LIM: |tip_dx| must stay below LIM after time T (a stability
check: the references stay within 2-3 cm after 0.5 s; an unstable coupling
swings the plate by 10 cm or more); a run with no sample after T has "no data"
and fails the check. Also reported: the share of [0, tmax]
during which the run lies inside the envelope of all eleven references.
Exit 1 if a check is asked for and fails."""
import argparse, csv, json, os, sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REF = os.path.join(HERE, '..', 'cases', 'dambreak_elastic_plate', 'walhorn2005.csv')


def load_ref():
    s = {}
    with open(REF) as f:
        for r in csv.DictReader(l for l in f if not l.startswith('#')):
            s.setdefault(r['series'], []).append((float(r['x']), float(r['y'])))
    return {k: np.array(sorted(v)) for k, v in s.items()}


def load_run(run):
    with open(os.path.join(run, 'probes.csv')) as f:
        rows = list(csv.DictReader(l for l in f if not l.startswith('#')))  # '#': provenance
    t = np.array([float(r['time']) for r in rows])
    d = np.array([float(r['tip_dx']) for r in rows])
    return t, d


def metrics(run, ref, tmax):
    t, d = load_run(run)
    early = t <= 0.4
    k = int(np.argmax(d[early]))
    w = ref['walhorn2005_fem']
    grid = np.linspace(0.0, min(tmax, t[-1], w[-1, 0]), 400)
    diff = np.interp(grid, t, d) - np.interp(grid, w[:, 0], w[:, 1])
    # envelope of every reference that covers the time (all do to ~0.7 s)
    env = np.linspace(0.0, min(tmax, t[-1]), 400)
    lo, hi = np.full(env.shape, np.inf), np.full(env.shape, -np.inf)
    for c in ref.values():
        cover = (env >= c[0, 0]) & (env <= c[-1, 0])
        y = np.interp(env, c[:, 0], c[:, 1])
        lo[cover] = np.minimum(lo[cover], y[cover])
        hi[cover] = np.maximum(hi[cover], y[cover])
    mine = np.interp(env, t, d)
    have = np.isfinite(lo)
    inside = float(np.mean((mine[have] >= lo[have] - 1e-3) & (mine[have] <= hi[have] + 1e-3)))
    out = {'run': run, 'inside_reference_envelope': inside, 'peak_m': float(d[early][k]), 'peak_time_s': float(t[early][k]),
           'rms_vs_walhorn_m': float(np.sqrt(np.mean(diff ** 2))),
           'max_abs_vs_walhorn_m': float(np.max(np.abs(diff))), 'tmax': float(grid[-1])}
    s = os.path.join(run, 'summary.json')
    if os.path.exists(s):
        with open(s) as f:
            j = json.load(f)
        out['wall_seconds'] = j.get('wall_seconds')
        out['messaging_fraction'] = j.get('messaging_fraction')
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--tmax', type=float, default=1.0)
    ap.add_argument('--plot')
    ap.add_argument('--labels')
    ap.add_argument('--peak-band', nargs=2, type=float)
    ap.add_argument('--peak-time', nargs=2, type=float)
    ap.add_argument('--max-after', nargs=2, type=float)
    ap.add_argument('--json', action='store_true')
    a = ap.parse_args()
    ref = load_ref()
    res = [metrics(r, ref, a.tmax) for r in a.runs]
    ok = True
    for m in res:
        if a.peak_band and not (a.peak_band[0] <= m['peak_m'] <= a.peak_band[1]):
            ok = False
        if a.peak_time and not (a.peak_time[0] <= m['peak_time_s'] <= a.peak_time[1]):
            ok = False
        if a.max_after:
            t, d = load_run(m['run'])
            late = np.abs(d[t > a.max_after[0]])
            m['max_abs_after_m'] = float(late.max()) if late.size else None
            if m['max_abs_after_m'] is None or m['max_abs_after_m'] >= a.max_after[1]:
                ok = False
        if a.json:
            print(json.dumps(m))
        else:
            print(f"{m['run']}: peak {100 * m['peak_m']:.2f} cm at {m['peak_time_s']:.3f} s; "
                  f"vs Walhorn FEM over [0, {m['tmax']:.2f}] s: RMS {100 * m['rms_vs_walhorn_m']:.2f} cm, "
                  f"max {100 * m['max_abs_vs_walhorn_m']:.2f} cm; inside the references' envelope "
                  f"{100 * m['inside_reference_envelope']:.0f}% of the time"
                  + ('' if not a.max_after else
                     f"; max |dx| after {a.max_after[0]} s: {100 * m['max_abs_after_m']:.2f} cm"
                     if m['max_abs_after_m'] is not None else
                     f"; max |dx| after {a.max_after[0]} s: no data (the run ends at "
                     f"{load_run(m['run'])[0][-1]:g} s)"))
    if a.plot:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(8, 4.5))
        for name, c in ref.items():
            style = dict(color='k', lw=2) if name == 'walhorn2005_fem' else dict(color='0.7', lw=0.8)
            ax.plot(c[:, 0], 100 * c[:, 1], label=name if name == 'walhorn2005_fem' else None, **style)
        ax.plot([], [], color='0.7', lw=0.8, label='ten other methods')
        labels = a.labels.split(',') if a.labels else a.runs
        for r, lab in zip(a.runs, labels):
            t, d = load_run(r)
            ax.plot(t, 100 * d, lw=1.5, label=lab)
        ax.set_xlim(0, 2)
        ax.set_xlabel('t (s)')
        ax.set_ylabel('tip displacement x (cm)')
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
    sys.exit(0 if ok else 1)


if __name__ == '__main__':
    main()
