#!/usr/bin/python3
"""Where the interior fluid at P = 0 is: snapshots of runs side by side
(docs/pressure.md, "Spray"). Black: walls and solid; blue: free surface;
grey: interior with P > 0; red: interior at P = 0 (the flicker measure's
particles).

usage: spray_picture.py OUT.png RUN [RUN...] --snaps 6 10 14 [--xlim 0 0.6 --ylim 0 0.35]"""
import argparse, os

import h5py
import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('out')
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--snaps', type=int, nargs='+', default=[6, 10, 14])
    ap.add_argument('--xlim', type=float, nargs=2, default=[0.0, 0.6])
    ap.add_argument('--ylim', type=float, nargs=2, default=[0.0, 0.35])
    a = ap.parse_args()
    fig, axs = plt.subplots(len(a.runs), len(a.snaps), figsize=(5 * len(a.snaps), 3.4 * len(a.runs)),
                            squeeze=False)
    for row, run in zip(axs, a.runs):
        for ax, k in zip(row, a.snaps):
            with h5py.File(os.path.join(run, 'fluid_%06d.h5' % k), 'r') as f:
                x = f['particles/position'][:, :2]
                p = f['particles/pressure'][:]
                s = f['particles/free_surface'][:]
                ty = f['particles/type'][:]
                t = float(f.attrs['time'])
            fl = ty == 0
            inner = fl & (s == 0)
            zero = inner & (p == 0.0)
            ax.scatter(x[~fl, 0], x[~fl, 1], s=1, c='k')
            ax.scatter(x[fl & (s == 1), 0], x[fl & (s == 1), 1], s=2, c='b')
            ax.scatter(x[inner & ~zero, 0], x[inner & ~zero, 1], s=2, c='0.7')
            ax.scatter(x[zero, 0], x[zero, 1], s=3, c='r')
            ax.set_aspect('equal')
            ax.set_xlim(*a.xlim)
            ax.set_ylim(*a.ylim)
            ax.set_title('%s, t = %.2f s: %.0f%% of interior at P = 0'
                         % (os.path.basename(run.rstrip('/')), t, 100 * zero.sum() / max(inner.sum(), 1)),
                         fontsize=9)
    fig.tight_layout()
    fig.savefig(a.out, dpi=70)


if __name__ == '__main__':
    main()
