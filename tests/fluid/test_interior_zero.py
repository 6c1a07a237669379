#!/usr/bin/python3
"""bench/interior_zero.py's test of where a zero sits, on lattices whose
pressure is known.

A pool 20 dp deep under hydrostatic pressure with one interior particle
zeroed 10 dp down: the water around it must read rho g (10 dp) within 5%
(its neighbours within 2.1 dp sit symmetrically about it, so their mean is
its own depth's pressure; 5% leaves room for the lattice), far above the
rho g dp that separates loaded water from water at the air's pressure. A
sheet 4 dp thick at P = 0 (in free fall) with one particle zeroed: the water
around it must read 0. Walls and solids (type != 0) must not count: a wall
row at 1 MPa beside the sheet must leave it at 0. Exit 0 if all hold."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'bench'))
from interior_zero import neighbour_pressure  # noqa: E402

RHO, G, DP = 1000.0, 9.81, 0.01


def lattice(nx, ny):
    ii, jj = np.meshgrid(np.arange(nx), np.arange(ny), indexing='ij')
    return np.column_stack([ii.ravel() * DP, jj.ravel() * DP])


def check(name, x, p, fluid, zero_at, want, tol, fails):
    i = int(np.argmin(np.sum((x - zero_at) ** 2, axis=1)))
    p = p.copy()
    p[i] = 0.0
    got = neighbour_pressure(x, p, fluid, np.array([i]), DP)
    got = float(got[0]) if got.size else float('nan')
    print('%s: the water around the zero reads %.2f Pa (want %.2f +- %.2f)' % (name, got, want, tol))
    if not abs(got - want) <= tol:
        fails.append(name)


def main():
    fails = []
    x = lattice(30, 20)
    depth = (19 * DP - x[:, 1])
    p = RHO * G * depth
    fluid = np.ones(len(x), bool)
    want = RHO * G * 10 * DP
    check('pool, 10 dp deep', x, p, fluid, (15 * DP, 9 * DP), want, 0.05 * want, fails)
    xs = lattice(30, 4)
    wall = np.column_stack([np.arange(30) * DP, np.full(30, -DP)])
    x2 = np.vstack([xs, wall])
    p2 = np.concatenate([np.zeros(len(xs)), np.full(30, 1e6)])
    fluid2 = np.concatenate([np.ones(len(xs), bool), np.zeros(30, bool)])
    check('sheet at P = 0 beside a wall at 1 MPa', x2, p2, fluid2, (15 * DP, 0.0), 0.0, 1e-9, fails)
    for f in fails:
        print('FAIL: ' + f)
    return 1 if fails else 0


if __name__ == '__main__':
    sys.exit(main())
