#!/usr/bin/python3
"""The reference pressures of test_fluid_step's dam break at t = 0
(tests/fluid/test_fluid_step.c, test_dambreak_first_step): the incompressible
pressure of the column the instant the gate is gone, Laplace's equation on
the region the 8 mm particles span,
    0 < x < 0.140 (P = 0 at the right column's centres),
    0 < y < 0.284 (P = 0 at the top row's centres),
    dP/dx = 0 on the left wall, dP/dy = -rho g on the floor,
by second-order finite differences on 280 x 568 cells (h = 0.5 mm), solved
directly (scipy), read at the four points of the test by bilinear
interpolation of the cell centres.

    /usr/bin/python3 tests/fluid/scripts/potential_flow_ref.py [--cells NX NY]

Prints the four pressures (Pa) in the test's order; with the default grid
they are the test's 976.7, 220.6, 807.7, 161.1 Pa. --cells 140 284 (half the
resolution) gives the same to 0.1 Pa, so the grid is converged far below the
test's tolerance. About 30 s (the direct solve of 159k unknowns)."""
import argparse

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

RHO, G = 1000.0, 9.81
W, H = 0.140, 0.284
POINTS = [(0.004, 0.004), (0.004, 0.140), (0.068, 0.004), (0.068, 0.140)]


def solve(nx, ny):
    hx, hy = W / nx, H / ny
    n = nx * ny
    idx = np.arange(n).reshape(ny, nx)  # [j, i]: cell (i + 1/2) hx, (j + 1/2) hy
    rows, cols, vals = [], [], []
    b = np.zeros(n)

    def add(r, c, v):
        rows.append(r)
        cols.append(c)
        vals.append(v)

    for j in range(ny):
        for i in range(nx):
            k = idx[j, i]
            diag = 0.0
            # x neighbours: left wall Neumann (dP/dx = 0), right face Dirichlet P = 0
            if i > 0:
                add(k, idx[j, i - 1], 1.0 / hx**2)
                diag -= 1.0 / hx**2
            if i < nx - 1:
                add(k, idx[j, i + 1], 1.0 / hx**2)
                diag -= 1.0 / hx**2
            else:  # ghost at the face: P = 0 there, -P_k mirrored
                diag -= 2.0 / hx**2
            # y neighbours: floor Neumann dP/dy = -rho g, top Dirichlet P = 0
            if j > 0:
                add(k, idx[j - 1, i], 1.0 / hy**2)
                diag -= 1.0 / hy**2
            else:  # (P_k - P_ghost) / hy = -rho g: P_ghost = P_k + rho g hy
                b[k] -= RHO * G * hy / hy**2
            if j < ny - 1:
                add(k, idx[j + 1, i], 1.0 / hy**2)
                diag -= 1.0 / hy**2
            else:
                diag -= 2.0 / hy**2
            add(k, k, diag)
    A = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    p = spla.spsolve(A.tocsc(), b).reshape(ny, nx)
    xc = (np.arange(nx) + 0.5) * hx
    yc = (np.arange(ny) + 0.5) * hy
    out = []
    for x, y in POINTS:
        fi = np.interp(x, xc, np.arange(nx))
        fj = np.interp(y, yc, np.arange(ny))
        i0, j0 = int(np.floor(fi)), int(np.floor(fj))
        i1, j1 = min(i0 + 1, nx - 1), min(j0 + 1, ny - 1)
        a, c = fi - i0, fj - j0
        out.append((1 - a) * (1 - c) * p[j0, i0] + a * (1 - c) * p[j0, i1] +
                   (1 - a) * c * p[j1, i0] + a * c * p[j1, i1])
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--cells', type=int, nargs=2, default=(280, 568))
    a = ap.parse_args()
    for (x, y), p in zip(POINTS, solve(*a.cells)):
        print(f'P({x:.3f}, {y:.3f}) = {p:.1f} Pa')


if __name__ == '__main__':
    main()
