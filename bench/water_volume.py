#!/usr/bin/python3
"""How much room the water takes, snapshot by snapshot: a check of volume
conservation in still water (docs/pressure.md, "Still water"; docs/hard_cases.md,
"The drift, measured again").

usage: bench/water_volume.py RUN [--x0 X0 --x1 X1]

For each fluid snapshot of RUN: the mean height of the fluid particles and the
mean height of the top sqrt(N) of them (the free surface's centres), between
x0 and x1 if given (one basin), the mean number density of the interior
particles (not on the free surface) and the largest speed. In still water on a
flat floor the mean height is half the depth, so its change over the run is
the water's change of volume (relative: change / mean height), whatever the
number density says."""
import argparse
import glob
import os

import h5py
import numpy as np


def rows(run, x0=None, x1=None):
    out = []
    for fn in sorted(glob.glob(os.path.join(run, 'fluid_*.h5'))):
        with h5py.File(fn, 'r') as f:
            t = float(f.attrs['time'])
            x = f['particles/position'][:]
            fluid = f['particles/type'][:] == 0
            surf = f['particles/free_surface'][:] != 0
            n = f['particles/number_density'][:]
            v = f['particles/velocity'][:]
        sel = fluid.copy()
        if x0 is not None:
            sel &= x[:, 0] >= x0
        if x1 is not None:
            sel &= x[:, 0] <= x1
        y = np.sort(x[sel, 1])
        k = max(1, int(np.sqrt(y.size)))
        interior = sel & ~surf
        out.append((t, y.mean(), y[-k:].mean(),
                    n[interior].mean() if interior.any() else float('nan'),
                    float(np.max(np.hypot(v[fluid, 0], v[fluid, 1]))) if fluid.any() else 0.0))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--x0', type=float)
    ap.add_argument('--x1', type=float)
    a = ap.parse_args()
    r = rows(a.run, a.x0, a.x1)
    if not r:
        raise SystemExit(f'{a.run}: no fluid snapshot (fluid_*.h5)')
    y0 = r[0][1]
    print('time (s), mean height (mm), change of volume, top (mm), interior number density, '
          'largest speed (m/s)')
    for t, ym, top, n, vmax in r:
        print(f'{t:.3f}, {1e3 * ym:.3f}, {100 * (ym / y0 - 1):+.2f}%, {1e3 * top:.3f}, '
              f'{n:.4f}, {vmax:.2g}')


if __name__ == '__main__':
    main()
