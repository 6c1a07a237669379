#!/usr/bin/python3
"""Snapshot pictures of a sloshing run at given instants, in the lab frame (the
tank drawn tilted by its angle then, as in the paper's Figs. 14 and 16): oil
particles coloured by pressure, the plate in orange, the tank's walls grey.

The solvers work in the tank's frame (docs/sloshing.md); positions are turned
into the lab's about the case's pivot by the angle theta(t) the run's
probes.csv reports (column tank_angle). Each instant takes the snapshot nearest
in time (the run needs output.interval dividing the instants: 0.01 s).

usage: bench/sloshing_pictures.py RUN --times 0.90 1.20 ... --out PNG
       [--title TEXT] [--cols 4]
"""
import argparse
import glob
import math
import os

import h5py
import numpy as np
import yaml

from probes_csv import probes_table


def snapshots(run, prefix):
    out = {}
    for p in glob.glob(os.path.join(run, f'{prefix}_*.h5')):
        with h5py.File(p, 'r') as f:
            out[float(f.attrs['time'])] = p
    return out


def nearest(snaps, t):
    k = min(snaps, key=lambda s: abs(s - t))
    return k, snaps[k]


def angle_at(run, t):
    d = probes_table(os.path.join(run, 'probes.csv'))
    return float(np.interp(t, d['time'], d['tank_angle']))


def to_lab(x, theta, pivot):
    c, s = math.cos(theta), math.sin(theta)
    r = x - pivot
    return np.column_stack([pivot[0] + c * r[:, 0] - s * r[:, 1], pivot[1] + s * r[:, 0] + c * r[:, 1]])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--times', type=float, nargs='+', required=True)
    ap.add_argument('--out', required=True)
    ap.add_argument('--title', default='')
    ap.add_argument('--cols', type=int, default=4)
    ap.add_argument('--pmax', type=float, default=None, help='colour scale top, Pa')
    a = ap.parse_args()
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    with open(os.path.join(a.run, 'case_resolved.yml')) as f:
        case = yaml.safe_load(f)
    pivot = np.array([float(case['motion']['pivot']['x']), float(case['motion']['pivot']['y'])]) \
        if case['motion']['kind'] != 'none' else np.zeros(2)
    W, H = float(case['fluid']['tank']['width']), float(case['fluid']['tank']['height'])
    fl, so = snapshots(a.run, 'fluid'), snapshots(a.run, 'solid')
    n = len(a.times)
    rows = (n + a.cols - 1) // a.cols
    fig, axs = plt.subplots(rows, a.cols, figsize=(3.2 * a.cols, 2.3 * rows + 0.4), squeeze=False)
    pmax = a.pmax
    for k, t in enumerate(a.times):
        ax = axs[k // a.cols][k % a.cols]
        tf, pf = nearest(fl, t)
        theta = math.radians(angle_at(a.run, tf))
        with h5py.File(pf, 'r') as f:
            x = f['particles/position'][:, :2]  # (x, y, 0) in the files
            typ = f['particles/type'][:]
            p = f['particles/pressure'][:]
        fluid = typ == 0
        wall = (typ == 1) | (typ == 2)
        if pmax is None:
            pmax = float(np.percentile(p[fluid], 99.5))
        xl = to_lab(x, theta, pivot)
        dp = float(case['dp'])
        s = max(0.05, (72.0 * 3.2 / 0.7 * dp) ** 2 * 0.5)
        ax.scatter(xl[wall, 0], xl[wall, 1], s=s, c='0.6', lw=0, rasterized=True)
        ax.scatter(xl[fluid, 0], xl[fluid, 1], s=s, c=p[fluid], cmap='viridis', vmin=0, vmax=pmax,
                   lw=0, rasterized=True)
        if so:
            ts, ps = nearest(so, t)
            with h5py.File(ps, 'r') as f:
                xs = to_lab(f['particles/position'][:, :2], theta, pivot)
            ax.scatter(xs[:, 0], xs[:, 1], s=s, c='tab:orange', lw=0, rasterized=True)
        ax.set_aspect('equal')
        ax.set_xlim(-0.02, W + 0.02)
        ax.set_ylim(-0.05, H + 0.02)  # the whole tank: the high filling splashes to the lid
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f't = {tf:.2f} s, {math.degrees(theta):+.1f} deg', fontsize=9)
    for k in range(n, rows * a.cols):
        axs[k // a.cols][k % a.cols].axis('off')
    if a.title:
        fig.suptitle(a.title, fontsize=10)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)


if __name__ == '__main__':
    main()
