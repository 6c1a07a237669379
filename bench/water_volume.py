#!/usr/bin/python3
"""How much room the water takes, snapshot by snapshot: a check of volume
conservation in still water (docs/pressure.md, "Still water"; docs/hard_cases.md,
"The drift, measured again").

usage: bench/water_volume.py RUN [--x0 X0 --x1 X1] [--dp DP] [--jitter]
       bench/water_volume.py --survey

For each fluid snapshot of RUN: the mean height of the fluid particles and the
mean height of the top sqrt(N) of them (the free surface's centres), between
x0 and x1 if given (one basin), the mean number density of the interior
particles (not on the free surface) and the largest speed. In still water on a
flat floor the mean height is half the depth, so its change over the run is
the water's change of volume (relative: change / mean height), whatever the
number density says.
--dp: also the interior particles' distance to their nearest neighbour and the
mean distance to their 4 nearest, in dp: how the lattice rearranges.
--jitter: the number density of a square lattice whose particles are moved at
random by 0.02-0.15 dp, at the same area, against the perfect lattice's (re =
2.1 dp, the MPS weight re/r - 1): the weight is convex in r, so disorder
raises the number density, and a correction that holds it at n0 then expands
the water by about as much; beside it, the quadratic weight of
fluid.density_weight = quadratic, which disorder raises about a third as much.
--survey (no RUN): the weights considered for fluid.density_weight, each
with its support: the rise of the sum on the lattice jittered by 0.1 dp, and
its deficit in the rows at and under a free surface (row 0 the surface
particles, row 1 the first row the PPE solves), as docs/pressure.md quotes
them."""
import argparse
import glob
import os

import h5py
import numpy as np


def rows(run, x0=None, x1=None, dp=None):
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
        sp = spacing(x, interior, dp) if dp and interior.any() else (float('nan'),) * 2
        out.append((t, y.mean(), y[-k:].mean(),
                    n[interior].mean() if interior.any() else float('nan'),
                    float(np.max(np.hypot(v[fluid, 0], v[fluid, 1]))) if fluid.any() else 0.0) + sp)
    return out


def spacing(x, sel, dp):
    """Mean nearest-neighbour distance and mean distance to the 4 nearest of
    the particles in sel, among all of x, in dp (brute force in chunks)."""
    idx = np.flatnonzero(sel)
    near, four = [], []
    for c in range(0, idx.size, 512):
        i = idx[c:c + 512]
        d = np.hypot(x[i, None, 0] - x[None, :, 0], x[i, None, 1] - x[None, :, 1])
        d[np.arange(i.size), i] = np.inf
        d = np.sort(d, axis=1)[:, :4]
        near.append(d[:, 0])
        four.append(d.mean(axis=1))
    return np.concatenate(near).mean() / dp, np.concatenate(four).mean() / dp


def jitter_table(re=2.1, n=40, seed=1):
    """n/n0 of a periodic square lattice (spacing 1) jittered by sigma, for
    Eq. 7's weight and for the quadratic one of fluid.density_weight
    ((1 - r/re)^2, the particle itself included)."""
    rng = np.random.default_rng(seed)
    g = np.stack(np.meshgrid(np.arange(n), np.arange(n)), -1).reshape(-1, 2).astype(float)
    weights = [(lambda q: 1 / q - 1, False), (lambda q: (1 - q) ** 2, True)]
    n0 = [lattice_sum(w, re, g, n, self_) for w, self_ in weights]
    out = []
    for s in (0.02, 0.05, 0.1, 0.15):
        x = (g + s * rng.standard_normal(g.shape)) % n
        out.append((s, *(lattice_sum(w, re, x, n, self_) / m for (w, self_), m in zip(weights, n0))))
    return out


# the candidates of --survey: q = r / re; 'self' adds w(0) (the particle itself)
SURVEY = [('Eq. 7 (re/r - 1)', lambda q: 1 / q - 1, 2.1, False),
          ('quadratic (1 - q)^2', lambda q: (1 - q) ** 2, 2.1, True),
          ('Wendland C2', lambda q: (1 - q) ** 4 * (1 + 4 * q), 2.1, True),
          ('Wendland C2', lambda q: (1 - q) ** 4 * (1 + 4 * q), 4.0, True),
          ('cubic spline', lambda q: np.where(q < 0.5, 1 - 6 * q ** 2 + 6 * q ** 3, 2 * (1 - q) ** 3), 3.0, True)]


def lattice_sum(w, re, x, n, self_):
    """Mean over x (periodic box n) of the sum of w(r/re) over the others
    within re, plus w(0) if self_."""
    tot = 0.0
    for c in range(0, len(x), 400):
        d = x[c:c + 400, None, :] - x[None, :, :]
        d -= n * np.round(d / n)
        r = np.hypot(d[..., 0], d[..., 1])
        m = (r > 0) & (r < re)
        tot += np.sum(w(r[m] / re))
    return tot / len(x) + (float(w(np.array(0.0))) if self_ else 0.0)


def surface_deficit(w, re, self_, rows=3):
    """The sum at rows 0, 1, ... under a flat free surface (the lattice y <= 0)
    against the full lattice's."""
    k = int(re) + 2
    a, b = np.meshgrid(np.arange(-k, k + 1), np.arange(-k, k + 1))

    def total(keep):
        r = np.hypot(a, b)[keep]
        m = (r > 0) & (r < re)
        return np.sum(w(r[m] / re)) + (float(w(np.array(0.0))) if self_ else 0.0)
    full = total(np.ones_like(a, bool))
    return [total(b <= row) / full - 1 for row in range(rows)]


def survey(n=40, seed=1, sigma=0.1):
    g = np.stack(np.meshgrid(np.arange(n), np.arange(n)), -1).reshape(-1, 2).astype(float)
    jit = (g + sigma * np.random.default_rng(seed).standard_normal(g.shape)) % n
    print(f'weight, support (dp): rise on a lattice jittered by {sigma} dp; deficit at rows 0, 1, 2 '
          'under a free surface')
    with np.errstate(divide='ignore'):
        for name, w, re, self_ in SURVEY:
            rise = lattice_sum(w, re, jit, n, self_) / lattice_sum(w, re, g, n, self_) - 1
            d = surface_deficit(w, re, self_)
            print(f'{name}, {re}: {100 * rise:+.2f}%; ' + ', '.join(f'{100 * v:+.1f}%' for v in d))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run', nargs='?')
    ap.add_argument('--survey', action='store_true')
    ap.add_argument('--x0', type=float)
    ap.add_argument('--x1', type=float)
    ap.add_argument('--dp', type=float)
    ap.add_argument('--jitter', action='store_true')
    a = ap.parse_args()
    if a.survey:
        survey()
        return
    if not a.run:
        ap.error('RUN is needed (or --survey)')
    if a.jitter:
        for sig, ratio, quad in jitter_table():
            print(f'square lattice jittered by {sig:.2f} dp: number density {100 * (ratio - 1):+.2f}% '
                  f'at the same area (quadratic weight: {100 * (quad - 1):+.2f}%)')
    r = rows(a.run, a.x0, a.x1, a.dp)
    if not r:
        raise SystemExit(f'{a.run}: no fluid snapshot (fluid_*.h5)')
    y0 = r[0][1]
    print('time (s), mean height (mm), change of volume, top (mm), interior number density, '
          'largest speed (m/s)' + (', nearest neighbour (dp), 4 nearest (dp)' if a.dp else ''))
    for t, ym, top, n, vmax, near, four in r:
        print(f'{t:.3f}, {1e3 * ym:.3f}, {100 * (ym / y0 - 1):+.2f}%, {1e3 * top:.3f}, '
              f'{n:.4f}, {vmax:.2g}' + (f', {near:.4f}, {four:.4f}' if a.dp else ''))


if __name__ == '__main__':
    main()
