#!/usr/bin/python3
"""How the rows held at P = 0 of a no-tension PPE depend on where the active
set starts (docs/pressure.md, "Water that holds no tension").

usage: bench/tension_sets.py DIR [DIR ...] [--sweeps 0,5,10,20] [--let-go N]

DIR holds what `fluid_solver CASE --out DIR --dump-ppe N` writes (ppe_A.mtx,
ppe_b.mtx). For each DIR, solved with direct factorisations:
  - from the clamped one-solve pressure, K projected Gauss-Seidel sweeps
    (P_i = max(0, (b_i - sum_j!=i a_ij P_j) / a_ii), rows in order) for each
    K of --sweeps: the rows they leave at 0, how many solves of the
    primal-dual active set (bench/ppe_terms.py's complementarity) then
    settle from that set, counting the one that confirms it, and the
    largest and RMS distance of the swept pressure from the settled one;
    K = 0 is the clamp itself;
  - with --let-go N, for the first N held rows of the settled solution, one
    at a time let go and the rest held, the largest change of the pressure:
    what a held set off by one row does to the solution."""
import argparse
import os
import sys

import numpy as np
import scipy.io
import scipy.sparse.linalg

import ppe_terms


def sweeps(A, b, P, k):
    """k projected Gauss-Seidel sweeps from P (a copy), in row order."""
    P = P.copy()
    diag = A.diagonal()
    for _ in range(k):
        for i in range(b.size):
            s, e = A.indptr[i], A.indptr[i + 1]
            v = b[i] - A.data[s:e] @ P[A.indices[s:e]] + diag[i] * P[i]
            P[i] = max(0.0, v / diag[i])
    return P


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dirs", nargs="+")
    ap.add_argument("--sweeps", default="0,5,10,20")
    ap.add_argument("--let-go", type=int, default=0, metavar="N")
    a = ap.parse_args()
    ks = [int(k) for k in a.sweeps.split(",")]
    for d in a.dirs:
        try:
            A = scipy.io.mmread(os.path.join(d, "ppe_A.mtx")).tocsr()
            b = np.asarray(scipy.io.mmread(os.path.join(d, "ppe_b.mtx"))).ravel()
        except (OSError, ValueError) as e:
            print(f"tension_sets.py: {d}: {e}", file=sys.stderr)
            return 1
        first = scipy.sparse.linalg.splu(A.tocsc()).solve(b)
        settled, _ = ppe_terms.complementarity(A, b, first)
        if settled is None:
            print(f"tension_sets.py: {d}: the active set did not settle", file=sys.stderr)
            return 1
        held = settled <= 0.0
        print(f"{d}: {b.size} rows; settled: {held.sum()} held, mean pressure "
              f"{settled.mean():.1f} Pa")
        for k in ks:
            P = sweeps(A, b, np.maximum(first, 0.0), k)
            e = P - settled
            print(f"  {k:3d} sweeps: {int((P <= 0.0).sum()):5d} at 0, "
                  f"{ppe_terms.complementarity(A, b, held=P <= 0.0)[1]} solves to settle; "
                  f"from the settled pressure at most {np.abs(e).max():.1f} Pa, "
                  f"RMS {np.sqrt(np.mean(e ** 2)):.2f} Pa")
        if a.let_go:
            moved = []
            for r in np.where(held)[0][:a.let_go]:
                h = held.copy()
                h[r] = False
                free = ~h
                Q = np.zeros(b.size)
                Q[free] = scipy.sparse.linalg.splu(A[free][:, free].tocsc()).solve(b[free])
                moved.append(np.abs(Q - settled).max())
            print(f"  one of the first {len(moved)} held rows let go: the pressure moves by at "
                  f"most {np.median(moved):.1f} Pa in the median, {min(moved):.1f}-"
                  f"{max(moved):.1f} Pa")
    return 0


if __name__ == "__main__":
    sys.exit(main())
