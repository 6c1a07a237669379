#!/usr/bin/python3
"""Checks that a fluid run stayed sound to its end.

usage: check_stable.py RUN_DIR [--t-end T] [--vmax 20]
  - summary.json (a fluid_solver or a coupler run): status ok and simulated
    time >= the run's end_time, and >= T if given (no NaN, no particle out of
    the tank, no time step below dt_min: fluid_step fails on those);
  - probes.csv: escaped == 0 and max_speed finite and below vmax at every
    probe time (a blow-up runs to hundreds of m/s; the dam break's fastest
    spray stays under 10 m/s).
Exit 0 if all hold, 1 otherwise."""
import argparse, math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fluid_run  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--t-end', type=float, default=None,
                    help='simulated time the run must cover (default: its own end_time)')
    ap.add_argument('--vmax', type=float, default=20.0)
    a = ap.parse_args()
    bad = []
    info, rows = fluid_run.load(a.run)
    why = fluid_run.unfinished(info, a.t_end)
    if why:
        bad.append(why)
    vm = max((r['max_speed'] for r in rows), default=float('nan'))
    esc = max((r['escaped'] for r in rows), default=0.0)
    print(f"reached t = {info['simulated_time']} s in {info['steps']} fluid steps; max speed "
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
