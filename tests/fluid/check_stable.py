#!/usr/bin/python3
"""Checks that a fluid run stayed sound to its end.

usage: check_stable.py RUN_DIR --t-end T [--vmax 20]
  - summary.json: status ok and simulated time >= T (no NaN, no particle out
    of the tank, no time step below dt_min: fluid_step fails on those);
  - probes.csv: escaped == 0 and max_speed finite and below vmax at every
    probe time (a blow-up runs to hundreds of m/s; the dam break's fastest
    spray stays under 10 m/s).
Exit 0 if all hold, 1 otherwise."""
import argparse, csv, json, math, os, sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--t-end', type=float, required=True)
    ap.add_argument('--vmax', type=float, default=20.0)
    a = ap.parse_args()
    bad = []
    with open(os.path.join(a.run, 'summary.json')) as f:
        s = json.load(f)
    if s.get('status') != 'ok' or s.get('simulated_time', 0.0) < a.t_end - 1e-9:
        bad.append(f"run stopped at t = {s.get('simulated_time')} s: {s.get('status')}: "
                   f"{s.get('message')}")
    with open(os.path.join(a.run, 'probes.csv')) as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    vm = max((r['max_speed'] for r in rows), default=float('nan'))
    esc = max((r['escaped'] for r in rows), default=0.0)
    print(f"reached t = {s.get('simulated_time')} s in {s.get('steps')} steps; max speed "
          f"{vm:.2f} m/s (limit {a.vmax}); escaped {esc:.0f}")
    if not all(math.isfinite(r['max_speed']) for r in rows) or not vm < a.vmax:
        bad.append('speed not finite or above the limit')
    if esc > 0:
        bad.append('particles left the tank')
    for b in bad:
        print('FAIL:', b)
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
