#!/usr/bin/python3
"""Checks a hydrostatic run (cases/hydrostatic) against the issue's targets.

usage: check_hydrostatic.py RUN_DIR [--depth 0.3] [--rho 1000] [--g 9.81]
                            [--p-tol 0.03] [--v-frac 0.01] [--t-end T]
                            [--surface-dp DP] [--t-start T0]
From RUN_DIR/probes.csv and summary.json (a fluid_solver or a coupler run):
  - the run finished (status ok, simulated time >= its end_time, and >= T if
    --t-end is given: the validation test asks for 2 s);
  - bottom_pressure (pressure on the floor, Pa) within p-tol of rho g h at every
    probe time after the first (t > 0), and on average; with --surface-dp DP,
    of rho g (h - DP/2): P = 0 holds at the surface particles' centres, DP/2
    below the water line, so that is what the discrete column carries;
    With --t-start T0, only the rows after T0 count for the pressure: a run
    at short steps rings for a few hundredths of a second as it leaves the
    hydrostatic guess, which is not what a long test watches for;
  - max_speed below v-frac * sqrt(g h) at every probe time;
  - escaped == 0 at every probe time.
Exit 0 if all hold, 1 otherwise; prints what it measured."""
import argparse, math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fluid_run  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--depth', type=float, default=0.3)
    ap.add_argument('--rho', type=float, default=1000.0)
    ap.add_argument('--g', type=float, default=9.81)
    ap.add_argument('--p-tol', type=float, default=0.03)
    ap.add_argument('--v-frac', type=float, default=0.01)
    ap.add_argument('--surface-dp', type=float, default=0.0,
                    help='reference rho g (h - DP/2) instead of rho g h')
    ap.add_argument('--t-end', type=float, default=None,
                    help='simulated time the run must cover (default: its own end_time)')
    ap.add_argument('--t-start', type=float, default=0.0,
                    help='judge the pressure only after this time (default: after t = 0)')
    a = ap.parse_args()
    info, rows = fluid_run.load(a.run)
    p_ref = a.rho * a.g * (a.depth - 0.5 * a.surface_dp)
    v_lim = a.v_frac * math.sqrt(a.g * a.depth)
    later = [r for r in rows if r['time'] > a.t_start]
    bad = []
    why = fluid_run.unfinished(info, a.t_end)
    if why:
        bad.append(why)
    if not later:
        bad.append('no probe rows after t = 0')
    else:
        perr = [r['bottom_pressure'] / p_ref - 1.0 for r in later]
        worst = max(perr, key=abs)
        mean = sum(r['bottom_pressure'] for r in later) / len(later) / p_ref - 1.0
        vmax = max(r['max_speed'] for r in rows)
        tv = max(rows, key=lambda r: r['max_speed'])['time']
        esc = max(r['escaped'] for r in rows)
        ref = 'rho g (h - dp/2)' if a.surface_dp else 'rho g h'
        print(f"bottom pressure: mean {100 * mean:+.2f}%, worst {100 * worst:+.2f}% of {ref} = "
              f"{p_ref:.1f} Pa (tolerance {100 * a.p_tol:.1f}%)")
        print(f"max speed {vmax:.5f} m/s at t = {tv:.3f} s (limit {v_lim:.5f} m/s = "
              f"{a.v_frac:g} sqrt(g h)); escaped particles: {esc:.0f}")
        if abs(worst) > a.p_tol or abs(mean) > a.p_tol:
            bad.append('bottom pressure out of tolerance')
        if vmax >= v_lim:
            bad.append('water not still')
        if esc > 0:
            bad.append('particles left the tank')
    for b in bad:
        print('FAIL:', b)
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
