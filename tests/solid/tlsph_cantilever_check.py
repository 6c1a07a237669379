#!/usr/bin/python3
"""Cantilever (paper 5.1) with the TLSPH solid: the frequency error and the
deflection discrepancy of probes.csv (tests/solid/cantilever_check.py) must lie
in bands [LO, HI] (percent), two-sided because at coarse resolution the TLSPH
beam is predictably too soft (docs/solid_models.md).

usage: tlsph_cantilever_check.py PROBES.csv --f-err LO HI --disc LO HI [--min-periods N]"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cantilever_check  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("probes")
    ap.add_argument("--f-err", nargs=2, type=float, required=True, metavar=("LO", "HI"))
    ap.add_argument("--disc", nargs=2, type=float, required=True, metavar=("LO", "HI"))
    ap.add_argument("--min-periods", type=float, default=2.0)
    a = ap.parse_args()
    r = cantilever_check.analyse(a.probes)
    print(json.dumps(r))
    bad = []
    if not a.f_err[0] <= r["f_err_pct"] <= a.f_err[1]:
        bad.append(f"f = {r['f']:.4f} Hz: error {r['f_err_pct']:+.2f}% outside "
                   f"[{a.f_err[0]}, {a.f_err[1]}]%")
    if not a.disc[0] <= r["disc_pct"] <= a.disc[1]:
        bad.append(f"max deflection {r['dmax_cm']:.2f} cm: discrepancy {r['disc_pct']:+.2f}% "
                   f"outside [{a.disc[0]}, {a.disc[1]}]%")
    if r["periods"] < a.min_periods:
        bad.append(f"only {r['periods']:.2f} periods simulated (need {a.min_periods})")
    for b in bad:
        print("FAIL: " + b, file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
