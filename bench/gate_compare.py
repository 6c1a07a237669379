#!/usr/bin/python3
"""Elastic-gate runs (cases/elastic_gate) side by side.

usage: gate_compare.py RUN_DIR [RUN_DIR...] [--labels A,B] [--plot FILE.png] [--json]
For each run: the largest opening of the free end (tip_dx) and its time, tip_dx
at t = 0.16 s (the experiment of Antoci et al. 2007: about 4.6 cm, the one
figure we have; no measured curve is in the repository), tip_dx at the end,
the largest tip_dy, the mean fluid force on the solid (solid_fx) over
[0.1, 0.2] s, wall time. --plot draws tip_dx, tip_dy and solid_fx."""
import argparse, csv, json, os

import numpy as np

EXP_T, EXP_DX = 0.16, 0.046


def load(run):
    with open(os.path.join(run, 'probes.csv')) as f:
        rows = list(csv.DictReader(l for l in f if not l.startswith('#')))  # '#': provenance
    col = lambda k: np.array([float(r[k]) for r in rows]) if rows and k in rows[0] else None
    return col('time'), col('tip_dx'), col('tip_dy'), col('solid_fx')


def metrics(run):
    t, dx, dy, fx = load(run)
    k = int(np.argmax(dx))
    m = {'run': run, 'end_s': float(t[-1]), 'max_dx_m': float(dx[k]), 'max_dx_time_s': float(t[k]),
         'dx_at_0.16_m': float(np.interp(EXP_T, t, dx)) if t[-1] >= EXP_T else None,
         'dx_end_m': float(dx[-1]), 'max_dy_m': float(dy.max())}
    if fx is not None:
        w = (t >= 0.1) & (t <= 0.2)
        m['mean_solid_fx_0.1_0.2_N_per_m'] = float(fx[w].mean()) if w.any() else None
    s = os.path.join(run, 'summary.json')
    if os.path.exists(s):
        with open(s) as f:
            j = json.load(f)
        m['wall_seconds'] = j.get('wall_seconds')
        m['coupling_steps'] = j.get('coupling_steps')
    return m


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--labels')
    ap.add_argument('--plot')
    ap.add_argument('--json', action='store_true')
    a = ap.parse_args()
    labels = a.labels.split(',') if a.labels else a.runs
    for r, lab in zip(a.runs, labels):
        m = metrics(r)
        if a.json:
            print(json.dumps(dict(m, label=lab)))
            continue
        at = f"{100 * m['dx_at_0.16_m']:.2f} cm" if m['dx_at_0.16_m'] is not None else 'n/a'
        print(f"{lab}: to {m['end_s']:.2f} s; max tip_dx {100 * m['max_dx_m']:.2f} cm at "
              f"{m['max_dx_time_s']:.3f} s; at 0.16 s {at} (experiment ~4.6); end "
              f"{100 * m['dx_end_m']:.2f} cm; max tip_dy {100 * m['max_dy_m']:.2f} cm; "
              f"wall {m.get('wall_seconds') or float('nan'):.0f} s")
    if a.plot:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 3, figsize=(14, 4))
        for r, lab in zip(a.runs, labels):
            t, dx, dy, fx = load(r)
            ax[0].plot(t, 100 * dx, label=lab)
            ax[1].plot(t, 100 * dy, label=lab)
            if fx is not None:
                ax[2].plot(t, fx, lw=0.8, label=lab)
        ax[0].plot([EXP_T], [100 * EXP_DX], 'ko', label='experiment (Antoci et al. 2007), 0.16 s')
        for x, name in zip(ax, ['free end dx (cm)', 'free end dy (cm)',
                                'fluid force on the solid, x (N/m), probe-interval mean']):
            x.set_xlabel('t (s)')
            x.set_ylabel(name)
            x.grid(alpha=0.3)
        ax[0].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)


if __name__ == '__main__':
    main()
