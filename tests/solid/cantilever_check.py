#!/usr/bin/python3
"""Cantilever beam (paper 5.1): frequency and maximum tip deflection from
probes.csv (column tip_dy, m), compared with Eq. 53-54.

usage: cantilever_check.py PROBES.csv [--freq-tol PCT] [--defl-max PCT] [--defl-min PCT]
                           [--min-periods N] [--modulus-factor F]
Prints one JSON line {f, f_err_pct, dmax_cm, disc_pct, periods}; with
tolerances given, exits 1 when a figure is outside them."""
import argparse
import json
import math
import sys

import numpy as np

# Eq. 53-54 with A = b, I = b^3/12 per metre depth (the paper's numbers).
L, B, RHO, E, G = 2.0, 0.1, 1000.0, 1.0e8, 9.81
I = B**3 / 12.0
F_REF = 1.875**2 / (2 * math.pi) * math.sqrt(E * I / (RHO * B * L**4))  # 1.277 Hz
D_REF = 2.0 * RHO * G * B * L**4 / (8.0 * E * I)                         # 0.4709 m


def crossings(t, y, direction):
    """Times where y crosses 0 going down (-1) or up (+1), linear interpolation."""
    s = np.sign(y)
    idx = np.nonzero((s[:-1] * direction < 0) & (s[1:] * direction >= 0))[0]
    return np.array([t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i]) for i in idx])


def analyse(path, factor=1.0):
    with open(path) as f:  # '#' lines: the run's provenance
        data = np.genfromtxt((l for l in f if not l.startswith("#")), delimiter=",", names=True)
    t, dy = data["time"], data["tip_dy"]
    if not np.all(np.isfinite(dy)):
        raise SystemExit(f"{path}: non-finite tip_dy")
    # solid.plane_factor multiplies E: the frequency goes as its root, the deflection inversely
    f_ref, d_ref = F_REF * math.sqrt(factor), D_REF / factor
    y = dy - 0.5 * (dy.max() + dy.min())
    periods = []
    for direction in (-1, 1):
        c = crossings(t, y, direction)
        periods += list(np.diff(c))
    if not periods:
        raise SystemExit(f"{path}: less than one period of tip_dy (t_end = {t[-1]:g} s)")
    f = 1.0 / np.mean(periods)
    dmax = float(np.max(np.abs(dy)))
    return {
        "f": f,
        "f_err_pct": 100.0 * (f - f_ref) / f_ref,
        "dmax_cm": 100.0 * dmax,
        "disc_pct": 100.0 * (d_ref - dmax) / d_ref,
        "periods": t[-1] * f,
        "f_ref": f_ref,
        "dmax_ref_cm": 100.0 * d_ref,
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("probes")
    ap.add_argument("--freq-tol", type=float, help="max |f error|, percent")
    ap.add_argument("--freq-range", type=float, nargs=2, metavar=("LO", "HI"),
                    help="f error within [LO, HI], percent")
    ap.add_argument("--defl-max", type=float, help="max deflection discrepancy, percent")
    ap.add_argument("--defl-min", type=float, help="min deflection discrepancy, percent")
    ap.add_argument("--min-periods", type=float, help="min number of periods simulated")
    ap.add_argument("--modulus-factor", type=float, default=1.0,
                    help="the run's solid.plane_factor: E in the references times this")
    a = ap.parse_args()
    r = analyse(a.probes, a.modulus_factor)
    print(json.dumps(r))
    bad = []
    if a.freq_tol is not None and abs(r["f_err_pct"]) > a.freq_tol:
        bad.append(f"f = {r['f']:.4f} Hz is {r['f_err_pct']:+.2f}% off {r['f_ref']:.4f} Hz "
                   f"(tolerance {a.freq_tol}%)")
    if a.freq_range and not a.freq_range[0] <= r["f_err_pct"] <= a.freq_range[1]:
        bad.append(f"f = {r['f']:.4f} Hz is {r['f_err_pct']:+.2f}% off {r['f_ref']:.4f} Hz "
                   f"(allowed {a.freq_range[0]:+g}% to {a.freq_range[1]:+g}%)")
    if a.defl_max is not None and r["disc_pct"] > a.defl_max:
        bad.append(f"max deflection {r['dmax_cm']:.2f} cm: discrepancy {r['disc_pct']:.2f}% "
                   f"above {a.defl_max}%")
    if a.defl_min is not None and r["disc_pct"] < a.defl_min:
        bad.append(f"max deflection {r['dmax_cm']:.2f} cm: discrepancy {r['disc_pct']:.2f}% "
                   f"below {a.defl_min}%")
    if a.min_periods is not None and r["periods"] < a.min_periods:
        bad.append(f"only {r['periods']:.2f} periods simulated (need {a.min_periods})")
    for b in bad:
        print("FAIL: " + b, file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
