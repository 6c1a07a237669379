#!/usr/bin/python3
"""Where the interior fluid at P = 0 is, and whether that water has expanded
(docs/pressure.md, "The deep patches at P = 0, and the water's area").

usage: bench/interior_zero.py RUN [RUN ...] --dp DP [--after 0.05] [--deep 3]
                              [--pool XMAX YMAX] [--picture PNG --times T ...
                               [--box X0 X1 Y0 Y1]]

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
--pool XMAX YMAX: a last column, the share at P = 0 of the interior fluid in
the box x < XMAX, y < YMAX (the dam break on a plate: the pool upstream of
the plate's face and below its top, the water that loads the plate before
any overtops it), and a closing count over all snapshots of all RUNs: the
snapshots with more than 5% of the interior at P = 0, counting all of it,
only what lies 1.5 dp or more from the free surface, and only the pool; and
the share of all the interior particles at P = 0 that lie outside the pool
(docs/pressure.md, "Where the plate's interior at P = 0 is"); then, inside
and outside the pool, for the interior particles at P = 0, the mean
pressure of the fluid within 2.1 dp of each (median, 90th percentile and the
share under 1) in units of rho g dp (`--rho`, default 1000): one particle's
depth of water, the scale below which a pressure is the air's within the
resolution. A zero in water around it at that scale is the air's pressure in
a free jet; a zero in loaded water is a hole in the field. Last, how far the
zeros in loaded water lie from the nearest free-surface particle, and the
snapshots over 5% counting as holes also the zeros `--deep` dp or more from
the free surface whatever their neighbours (a patch at P = 0 deep in the
water has zeros around it too).
--picture PNG --times T ...: draws the first RUN's snapshots nearest to each
T: the fluid, its free-surface particles grey, the interior at P = 0 red,
the tank and (from the solid snapshot of that time) the solid black; --box
sets the frame (default: the fluid's extent).
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


def read_fluid(fn):
    """(time, type, pressure, free-surface flag, 2D positions) of a fluid snapshot."""
    with h5py.File(fn, 'r') as f:
        return (float(f.attrs['time']), f['particles/type'][:], f['particles/pressure'][:],
                f['particles/free_surface'][:], f['particles/position'][:][:, :2])


def in_pool(x, pool):
    """Positions x inside the box x < pool[0], y < pool[1]."""
    return (x[:, 0] < pool[0]) & (x[:, 1] < pool[1])


def snapshot(fn, dp, deep, pool=None):
    t, ptype, p, surf, x = read_fluid(fn)
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
    extra = None
    if pool is not None:
        inside = in_pool(x[interior], pool)
        around = neighbour_pressure(x, p, fluid, interior[zero], dp)
        extra = {'pool': float(np.mean(zero[inside])) if inside.any() else 0.0,
                 'zero': int(zero.sum()), 'outside': int((zero & ~inside).sum()),
                 'interior': int(interior.size),
                 # for each zero: the fluid's mean pressure around it, its
                 # distance to the surface (dp), whether it is in the pool
                 'around': around, 'dist': dist[zero], 'in_pool': inside[zero]}
    return (t, float(zero.mean()), [float(np.mean(zero & b)) for b in bands],
            float(np.mean(areas)) if areas else float('nan'), extra)


def neighbour_pressure(x, p, fluid, sel, dp):
    """For each particle of sel (interior particles at P = 0): the mean
    pressure of the fluid within 2.1 dp of it (Eq. 7's radius, the particle
    itself left out; surface particles count, at their P = 0; walls and
    solids do not). Near 0 where the particle sits in water at the air's
    pressure (a free jet), large where it is a hole in loaded water."""
    if not sel.size:
        return np.zeros(0)
    idx = np.where(fluid)[0]
    tree = cKDTree(x[idx])
    out = []
    for i, nb in zip(sel, tree.query_ball_point(x[sel], 2.1 * dp)):
        nb = [j for j in idx[nb] if j != i]
        out.append(float(np.mean(p[nb])) if nb else 0.0)
    return np.array(out)


def pool_share(fn, pool):
    """(time, share at P = 0 of the interior fluid in x < pool[0], y < pool[1])."""
    t, ptype, p, surf, x = read_fluid(fn)
    inside = (ptype == 0) & (surf == 0) & in_pool(x, pool)
    return t, float(np.mean(p[inside] == 0.0)) if inside.any() else 0.0


def solid_positions(run, t):
    best = None
    for fn in glob.glob(os.path.join(run, 'solid_*.h5')):
        with h5py.File(fn, 'r') as f:
            ts = float(f.attrs['time'])
            if best is None or abs(ts - t) < best[0]:
                best = (abs(ts - t), f['particles/position'][:][:, :2])
    return best[1] if best is not None else np.zeros((0, 2))


def picture(run, times, path, box=None):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    files = sorted(glob.glob(os.path.join(run, 'fluid_*.h5')))
    stamps = []
    for fn in files:
        with h5py.File(fn, 'r') as f:
            stamps.append(float(f.attrs['time']))
    cols = 2 if len(times) > 1 else 1
    rows = (len(times) + cols - 1) // cols
    fig, axs = plt.subplots(rows, cols, figsize=(7 * cols, 4.2 * rows), squeeze=False)
    for ax, t in zip(axs.flat, times):
        fn = files[int(np.argmin(np.abs(np.array(stamps) - t)))]
        t, ptype, p, surf, x = read_fluid(fn)
        fluid = ptype == 0
        zero = fluid & (surf == 0) & (p == 0.0)
        ax.scatter(x[fluid, 0], x[fluid, 1], s=3, c='lightblue')
        ax.scatter(x[fluid & (surf != 0), 0], x[fluid & (surf != 0), 1], s=3, c='grey')
        ax.scatter(x[zero, 0], x[zero, 1], s=7, c='red')
        ax.scatter(x[~fluid, 0], x[~fluid, 1], s=2, c='black')
        xs = solid_positions(run, t)
        ax.scatter(xs[:, 0], xs[:, 1], s=3, c='black')
        ax.set_title('t = %.3f s: %d of %d interior particles at P = 0'
                     % (t, zero.sum(), (fluid & (surf == 0)).sum()))
        ax.set_aspect('equal')
        if box:
            ax.set_xlim(box[0], box[1])
            ax.set_ylim(box[2], box[3])
        else:
            lo, hi = x[fluid].min(axis=0), x[fluid].max(axis=0)
            ax.set_xlim(lo[0] - 0.01, hi[0] + 0.01)
            ax.set_ylim(lo[1] - 0.01, hi[1] + 0.01)
    fig.tight_layout()
    fig.savefig(path, dpi=80)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--dp', type=float, required=True)
    ap.add_argument('--after', type=float, default=0.05)
    ap.add_argument('--deep', type=float, default=3.0)
    ap.add_argument('--pool', type=float, nargs=2, metavar=('XMAX', 'YMAX'))
    ap.add_argument('--rho', type=float, default=1000.0,
                    help='the fluid density for the pressure scale rho g dp (--pool)')
    ap.add_argument('--picture')
    ap.add_argument('--times', type=float, nargs='+', default=[])
    ap.add_argument('--box', type=float, nargs=4, metavar=('X0', 'X1', 'Y0', 'Y1'))
    a = ap.parse_args()
    if a.picture:
        if not a.times:
            ap.error('--picture needs --times')
        picture(a.runs[0], a.times, a.picture, a.box)
    counts = {'snapshots': 0, 'all': 0, 'beyond': 0, 'pool': 0, 'zero': 0, 'outside': 0,
              'holes': 0, 'patches': 0}
    table = []
    p_out, p_in, d_loaded = [], [], []
    head = a.rho * 9.81 * a.dp  # one particle's depth of water, Pa
    print('run, t (s): interior at P = 0 | of it: < 1.5 dp, 1.5-%g dp, > %g dp from the '
          'surface | deep cells\' mean area (dp^2)' % (a.deep, a.deep))
    for run in a.runs:
        rows = []
        files = sorted(glob.glob(os.path.join(run, 'fluid_*.h5')))
        if not files:
            print('interior_zero.py: %s: no fluid snapshot (fluid_*.h5)' % run, file=sys.stderr)
            return 1
        for fn in files:
            s = snapshot(fn, a.dp, a.deep, a.pool)
            if s is None or s[0] <= a.after:
                continue
            rows.append([s[0], s[1]] + s[2] + [s[3]])
            tail = ''
            if s[4] is not None:
                e = s[4]
                loaded = e['around'] > head
                # a zero deep in the water is a hole even where its neighbours
                # are zeros too (a patch at P = 0, not a jet's air pressure)
                patch = loaded | (e['dist'] >= a.deep)
                tail = ' | pool %5.1f%% | in loaded water %5.1f%% | or deep %5.1f%%' % (
                    100 * e['pool'], 100.0 * loaded.sum() / e['interior'],
                    100.0 * patch.sum() / e['interior'])
                counts['snapshots'] += 1
                counts['all'] += s[1] > 0.05
                counts['beyond'] += s[2][1] + s[2][2] > 0.05
                counts['pool'] += e['pool'] > 0.05
                counts['holes'] += loaded.sum() > 0.05 * e['interior']
                counts['patches'] += patch.sum() > 0.05 * e['interior']
                counts['zero'] += e['zero']
                counts['outside'] += e['outside']
                p_out.append(e['around'][~e['in_pool']])
                p_in.append(e['around'][e['in_pool']])
                d_loaded.append(e['dist'][loaded])
            print('%s %.4f: %5.1f%% | %5.1f%% %5.1f%% %5.1f%% | %.4f%s'
                  % (run, s[0], 100 * s[1], 100 * s[2][0], 100 * s[2][1], 100 * s[2][2], s[3],
                     tail))
        table.append(rows)
    if len(table) > 1:
        k = min(len(r) for r in table)
        m = np.mean([np.array(r[:k]) for r in table], axis=0)
        print('mean of %d runs:' % len(table))
        for row in m:
            print('  %.3f: %5.1f%% | %5.1f%% %5.1f%% %5.1f%% | %.4f'
                  % (row[0], 100 * row[1], 100 * row[2], 100 * row[3], 100 * row[4], row[5]))
    if a.pool is not None:
        c = counts
        print('snapshots over 5%%, of %d: %d of the interior, %d counting only the fluid 1.5 dp or '
              'more from the surface, %d in the pool; of the %d interior particles at P = 0, '
              '%.1f%% outside the pool'
              % (c['snapshots'], c['all'], c['beyond'], c['pool'], c['zero'],
                 100.0 * c['outside'] / max(c['zero'], 1)))
        print('snapshots with over 5%% of the interior at P = 0 in loaded water (the fluid within '
              '2.1 dp above rho g dp on average), of %d: %d; counting also the zeros %g dp or '
              'more from the free surface: %d' % (c['snapshots'], c['holes'], a.deep,
                                                  c['patches']))
        d = np.concatenate(d_loaded) if d_loaded else np.zeros(0)
        if d.size:
            print('the %d zeros in loaded water: distance to the nearest free-surface particle '
                  'under 1.5 dp %.1f%%, 1.5-3 dp %.1f%%, beyond %.1f%%, median %.2f dp'
                  % (d.size, 100 * np.mean(d < 1.5), 100 * np.mean((d >= 1.5) & (d < 3)),
                     100 * np.mean(d >= 3), np.median(d)))
        for name, ps in (('outside the pool', p_out), ('in the pool', p_in)):
            ps = np.concatenate(ps) if ps else np.zeros(0)
            if not ps.size:
                continue
            print('interior at P = 0 %s: %d; the mean pressure of the fluid within 2.1 dp of '
                  'each, in rho g dp (%.1f Pa): median %.2f, 90th percentile %.2f, under 1 '
                  'for %.1f%%' % (name, ps.size, head, np.median(ps) / head,
                                  np.percentile(ps, 90) / head, 100.0 * np.mean(ps < head)))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
