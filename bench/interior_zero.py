#!/usr/bin/python3
"""Where the interior fluid at P = 0 is, and whether that water has expanded
(docs/pressure.md, "The deep patches at P = 0, and the water's area").

usage: bench/interior_zero.py RUN [RUN ...] --dp DP [--after 0.05] [--deep 3]

For each fluid snapshot of each RUN after `--after` s: the share of the
interior fluid (type 0, not on the free surface) at P = 0, split by the
distance of each particle to its nearest free-surface fluid particle (under
1.5 dp, 1.5 to `--deep` dp, beyond), and for the particles beyond `--deep`
dp the mean area of their Voronoi cells in dp^2. A particle's Voronoi cell
is the room it takes whatever its neighbours' arrangement, where Eq. 7's
number density also rises with disorder (bench/water_volume.py --jitter),
so the cells' mean says whether the bulk has expanded (1.0 is the starting
lattice's area per particle). Particles near the surface are left out of the
mean: their cells reach into the air or are cut by it.
With several RUNs (realisations of one setting) a last block gives the
mean over the runs of each column at each snapshot index.
Exit 1 if a RUN has no fluid snapshot."""
import argparse
import glob
import os
import sys

import h5py
import numpy as np
from scipy.spatial import Voronoi, cKDTree


def polygon_area(v):
    x, y = v[:, 0], v[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1)))


def snapshot(fn, dp, deep):
    with h5py.File(fn, 'r') as f:
        t = float(f.attrs['time'])
        ptype = f['particles/type'][:]
        p = f['particles/pressure'][:]
        surf = f['particles/free_surface'][:]
        x = f['particles/position'][:][:, :2]
    fluid = ptype == 0
    interior = np.where(fluid & (surf == 0))[0]
    on_surface = fluid & (surf != 0)
    if not interior.size or not on_surface.any():
        return None
    dist = cKDTree(x[on_surface]).query(x[interior])[0] / dp
    zero = p[interior] == 0.0
    bands = [dist < 1.5, (dist >= 1.5) & (dist < deep), dist >= deep]
    vor = Voronoi(x)
    areas = []
    for i in interior[dist >= deep]:
        reg = vor.regions[vor.point_region[i]]
        if reg and -1 not in reg:
            areas.append(polygon_area(vor.vertices[reg]) / dp ** 2)
    return (t, float(zero.mean()), [float(np.mean(zero & b)) for b in bands],
            float(np.mean(areas)) if areas else float('nan'))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--dp', type=float, required=True)
    ap.add_argument('--after', type=float, default=0.05)
    ap.add_argument('--deep', type=float, default=3.0)
    a = ap.parse_args()
    table = []
    print('run, t (s): interior at P = 0 | of it: < 1.5 dp, 1.5-%g dp, > %g dp from the '
          'surface | deep cells\' mean area (dp^2)' % (a.deep, a.deep))
    for run in a.runs:
        rows = []
        files = sorted(glob.glob(os.path.join(run, 'fluid_*.h5')))
        if not files:
            print('interior_zero.py: %s: no fluid snapshot (fluid_*.h5)' % run, file=sys.stderr)
            return 1
        for fn in files:
            s = snapshot(fn, a.dp, a.deep)
            if s is None or s[0] <= a.after:
                continue
            rows.append([s[0], s[1]] + s[2] + [s[3]])
            print('%s %.4f: %5.1f%% | %5.1f%% %5.1f%% %5.1f%% | %.4f'
                  % (run, s[0], 100 * s[1], 100 * s[2][0], 100 * s[2][1], 100 * s[2][2], s[3]))
        table.append(rows)
    if len(table) > 1:
        k = min(len(r) for r in table)
        m = np.mean([np.array(r[:k]) for r in table], axis=0)
        print('mean of %d runs:' % len(table))
        for row in m:
            print('  %.3f: %5.1f%% | %5.1f%% %5.1f%% %5.1f%% | %.4f'
                  % (row[0], 100 * row[1], 100 * row[2], 100 * row[3], 100 * row[4], row[5]))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
