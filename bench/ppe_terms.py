#!/usr/bin/python3
"""What each part of the PPE's source contributes to the pressure of one step
(docs/pressure.md, "The two halves of the mixed source").

usage: bench/ppe_terms.py DIR [DIR ...] [--box X0 X1 Y0 Y1] [--json OUT]

DIR holds what `fluid_solver CASE --out DIR --dump-ppe N` writes: the PPE of
the run's N-th step (ppe_A.mtx, ppe_b.mtx) and the parts its rhs is the sum
of (ppe_terms.csv): the walls' hydrostatic extrapolation (ghost), Eq. 23's
density error, the compressibility's memory of the last pressure, and the
mixed source's divergence. The PPE is linear, so the pressure of the step
(before the clamp) is the sum of the pressures each part alone asks for.
For each DIR this solves A P_k = b_k for each part k with a direct
factorisation and prints, over all rows, over the rows the step leaves at
P <= 0 and (--box) over the rows in a box of the plane, the mean of each
part's pressure and of their sum, in Pa. A zero where the density part is
strongly negative and the divergence part strongly positive is a place
where the two halves of the mixed source nearly cancel; a step-to-step swing
of either then moves the sum across zero. It also prints how many rows the
same system leaves at P <= 0 when the water holds no tension (the
complementarity problem fluid.tension_solves solves, here with direct
solves; docs/pressure.md, "Water that holds no tension"), and with --json,
where the record has the solver's `pressure` column, how far that is from
this solution.

Exit 1 if a file is missing or unreadable, or if the parts do not add up to
ppe_b.mtx (relative 1e-9): the dump would not be the system that was solved."""
import argparse
import json
import os
import sys

import numpy as np
import scipy.io
import scipy.sparse.linalg

from probes_csv import probes_table

PARTS = ("ghost", "density", "compressibility", "divergence")


def read_dir(d):
    """(A as CSC, b, positions, parts as columns) of one dump."""
    A = scipy.io.mmread(os.path.join(d, "ppe_A.mtx")).tocsc()
    b = np.asarray(scipy.io.mmread(os.path.join(d, "ppe_b.mtx"))).ravel()
    rows = rows_of(d)
    if rows.size != b.size:
        raise ValueError(f"ppe_terms.csv has {rows.size} rows, ppe_b.mtx {b.size}")
    missing = [p for p in PARTS + ("x", "y") if p not in rows.dtype.names]
    if missing:
        raise ValueError(f"ppe_terms.csv: no column {', '.join(missing)}")
    parts = np.column_stack([rows[p] for p in PARTS])
    xy = np.column_stack([rows["x"], rows["y"]])
    return A, b, xy, parts


def rows_of(d):
    return probes_table(os.path.join(d, "ppe_terms.csv"))


def decompose(A, b, parts):
    """The pressure each part asks for (columns), and the mismatch of the
    parts' sum against b relative to b's size."""
    scale = max(np.abs(b).max(), 1e-300)
    mismatch = np.abs(parts.sum(axis=1) - b).max() / scale
    lu = scipy.sparse.linalg.splu(A)
    P = np.column_stack([lu.solve(parts[:, k]) for k in range(parts.shape[1])])
    return P, mismatch


def complementarity(A, b, first=None, held=None, max_solves=50):
    """The pressure with no tension, as fluid.tension_solves computes it but
    with direct solves: P >= 0, A P = b where P > 0, A P - b >= 0 where P = 0
    (the water there may only expand). A primal-dual active set: hold the
    rows that come out negative at 0, let go the held rows whose equation
    asks for a pressure, until the set settles. Every row may be held: the
    dumps this reads have fluid rows only (walls and solids as ghosts).
    first: the one-solve answer A^-1 b if the caller has it; held: the rows
    to hold first instead of its negative ones. Returns (P, solves after the
    first, counting the one that confirms the set); None for P if it did not
    settle."""
    n = b.size
    A = A.tocsr()
    if held is None:
        P = scipy.sparse.linalg.splu(A.tocsc()).solve(b) if first is None else first
        held = P < 0.0
        if not held.any():
            return P, 0
    for solves in range(1, max_solves + 1):
        free = ~held
        P = np.zeros(n)
        if free.any():
            P[free] = scipy.sparse.linalg.splu(A[free][:, free].tocsc()).solve(b[free])
        w = A @ P - b
        new = np.where(held, w >= 0.0, P < 0.0)
        if (new == held).all():
            return P, solves
        held = new
    return None, max_solves


def means(P, mask):
    if not mask.any():
        return None
    return {name: float(P[mask, k].mean()) for k, name in enumerate(PARTS)} | {
        "sum": float(P[mask].sum(axis=1).mean()), "rows": int(mask.sum())}


def line(label, m):
    if m is None:
        return f"  {label:<18} no rows"
    return (f"  {label:<18} {m['rows']:6d} rows | " +
            " ".join(f"{name} {m[name]:9.1f}" for name in PARTS) + f" | sum {m['sum']:9.1f} Pa")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dirs", nargs="+")
    ap.add_argument("--box", nargs=4, type=float, metavar=("X0", "X1", "Y0", "Y1"))
    ap.add_argument("--json", help="write the figures of every DIR here")
    a = ap.parse_args()
    out = {}
    for d in a.dirs:
        try:
            A, b, xy, parts = read_dir(d)
        except (OSError, ValueError) as e:
            print(f"ppe_terms.py: {d}: {e}", file=sys.stderr)
            return 1
        P, mismatch = decompose(A, b, parts)
        if mismatch > 1e-9:
            print(f"ppe_terms.py: {d}: the parts differ from ppe_b.mtx by {mismatch:.2e} of its "
                  "largest entry: not the system that was solved", file=sys.stderr)
            return 1
        total = P.sum(axis=1)
        zero = total <= 0.0
        rec = {"rows": int(b.size), "at_zero": int(zero.sum()),
               "all": means(P, np.ones(b.size, bool)), "zero": means(P, zero)}
        released, solves = complementarity(A, b, total)
        if released is not None:
            rec["released_at_zero"] = int((released <= 0.0).sum())
            rec["released_solves"] = solves
            rows = rows_of(d)
            if "pressure" in rows.dtype.names:
                rec["pressure_vs_released"] = float(np.abs(rows["pressure"] - released).max())
        print(f"{d}: {b.size} rows, {zero.sum()} at P <= 0 ({100.0 * zero.mean():.1f}%); "
              + (f"with no tension {rec['released_at_zero']} ({solves} more solves); "
                 if released is not None else "no tension: did not settle; ")
              + "mean pressure of each part of the source:")
        print(line("all rows", rec["all"]))
        print(line("rows at P <= 0", rec["zero"]))
        if a.box:
            x0, x1, y0, y1 = a.box
            inbox = (xy[:, 0] >= x0) & (xy[:, 0] <= x1) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1)
            rec["box"] = means(P, inbox)
            rec["box_at_zero"] = int((inbox & zero).sum())
            print(line("the box", rec["box"]) +
                  (f", {rec['box_at_zero']} of them at P <= 0" if inbox.any() else ""))
        out[d] = rec
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(out, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
