#!/usr/bin/python3
"""Fluid inside a clamped plate's foot (docs/pressure.md, "Walls that slip in
Eq. 10" and "The divergence on the Laplacian's stencil").

usage: bench/plate_foot.py RUN [--x0 0.304] [--x1 0.308] [--height 0.006]

RUN: a coupled run with fluid snapshots. For each snapshot, the fluid
particles within --height of the floor whose centre lies between the plate's
faces x0 and x1 (the plate's foot bends little, so its faces stay there).
Prints the snapshots with any, the closest approach to a face (negative:
inside) and the tank guard uses from fluid_summary.json."""
import argparse, glob, json, os

import h5py
import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--x0', type=float, default=0.304)
    ap.add_argument('--x1', type=float, default=0.308)
    ap.add_argument('--height', type=float, default=0.006)
    a = ap.parse_args()
    mid = 0.5 * (a.x0 + a.x1)
    files = sorted(glob.glob(os.path.join(a.run, 'fluid_*.h5')))
    if not files:
        raise SystemExit('plate_foot: no fluid snapshot in %s' % a.run)
    inside, closest = 0, np.inf
    for fn in files:
        with h5py.File(fn, 'r') as f:
            ty = f['particles/type'][:]
            x = f['particles/position'][:][:, :2]
        low = (ty == 0) & (x[:, 1] < a.height)
        gap = np.where(x[low, 0] > mid, x[low, 0] - a.x1, a.x0 - x[low, 0])
        if gap.size:
            closest = min(closest, gap.min())
            inside += bool((gap < 0).any())
    guard = json.load(open(os.path.join(a.run, 'fluid_summary.json'))).get('wall_guard_uses')
    print('%s: %d snapshots, %d with fluid between the faces; closest to a face %.2f mm '
          '(negative: inside); tank guard uses %s' % (a.run, len(files), inside, 1000 * closest, guard))


if __name__ == '__main__':
    main()
