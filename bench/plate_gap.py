#!/usr/bin/python3
"""The oil beside the sloshing plate, snapshot by snapshot (docs/sloshing.md,
"Why 0.8 and 0.5 mm"): how far the nearest oil stands from each face of the
plate, in spacings (1 on the lattice), and its pressure against the same rows
far from the plate.

usage: bench/plate_gap.py RUN DP [--far X]

For each snapshot k of RUN (fluid_K.h5 with solid_K.h5), over the rows
y = 10-85 mm every 5 mm: the plate's faces are its outermost particles in the
row; the gap is the distance to the nearest oil particle on each side; the
pressure 'beside' is the mean over the oil within 1.9 spacings of a face,
'near' within 6 spacings, 'far' the same rows within 3 spacings of x = X
(default 0.15 m); 'at 0' the share of the oil beside the faces at P = 0."""
import argparse, glob, os, sys

import numpy as np

try:
    import h5py
except ImportError:
    sys.exit('plate_gap: needs h5py (apt-get install python3-h5py)')


def snapshot(run, k, dp, xfar):
    F = h5py.File(os.path.join(run, f'fluid_{k:06d}.h5'))['particles']
    S = h5py.File(os.path.join(run, f'solid_{k:06d}.h5'))['particles']
    x, p = F['position'][:], F['pressure'][:]
    oil = F['type'][:] == 0
    xs = S['position'][:]
    gl, gr, beside, near, far = [], [], [], [], []
    for y in np.arange(0.010, 0.0851, 0.005):
        ss = np.abs(xs[:, 1] - y) < 0.6 * dp
        row = oil & (np.abs(x[:, 1] - y) < 0.6 * dp)
        if not ss.any() or not row.any():
            continue
        a, b = xs[ss, 0].min(), xs[ss, 0].max()
        left, right = row & (x[:, 0] < a), row & (x[:, 0] > b)
        if left.any():
            gl.append((a - x[left, 0].max()) / dp)
        if right.any():
            gr.append((x[right, 0].min() - b) / dp)
        side = row & (((x[:, 0] < a) & (x[:, 0] > a - 1.9 * dp)) |
                      ((x[:, 0] > b) & (x[:, 0] < b + 1.9 * dp)))
        beside.append(p[side])
        near.append(p[row & (((x[:, 0] < a) & (x[:, 0] > a - 6 * dp)) |
                             ((x[:, 0] > b) & (x[:, 0] < b + 6 * dp)))])
        far.append(p[row & (np.abs(x[:, 0] - xfar) < 3 * dp)])
    cat = np.concatenate
    return (min(gl), max(gl), min(gr), max(gr), cat(beside).mean(), np.mean(cat(beside) <= 0.0),
            cat(near).mean(), cat(far).mean())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('run')
    ap.add_argument('dp', type=float)
    ap.add_argument('--far', type=float, default=0.15)
    a = ap.parse_args()
    ks = sorted(int(os.path.basename(f)[6:12]) for f in glob.glob(os.path.join(a.run, 'fluid_0*.h5')))
    if not ks:
        sys.exit(f'plate_gap: {a.run}: no fluid snapshots (output.interval > 0)')
    print('| snapshot | gap left (spacings) | gap right | p beside the faces (Pa) | beside at P = 0 '
          '| p within 6 spacings | p far, same rows |')
    print('|---|---|---|---|---|---|---|')
    for k in ks:
        if not os.path.exists(os.path.join(a.run, f'solid_{k:06d}.h5')):
            continue
        g0, g1, g2, g3, pb, z, pn, pf = snapshot(a.run, k, a.dp, a.far)
        print(f'| {k} | {g0:.2f}-{g1:.2f} | {g2:.2f}-{g3:.2f} | {pb:.0f} | {100 * z:.0f}% | '
              f'{pn:.0f} | {pf:.0f} |')


if __name__ == '__main__':
    main()
