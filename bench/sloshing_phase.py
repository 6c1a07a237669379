#!/usr/bin/python3
"""The plate's tip against the tank's roll in a sloshing run: the first
harmonics (at the roll's period) of tip_dx and of the push -theta (the tilted
gravity's pull along x) over whole periods, and how far the tip's lags the
push's.

The paper's metric (bench/sloshing_runs.py) is a peak-to-peak amplitude; two
runs can swing as far and still move differently. A damped response to the
push lags it by 0 (quasi-static) to about 90 degrees (at resonance, where both
cases are forced). Whole periods only: a partial cycle biases the harmonic.
tests/coupler/sloshing_check.py checks the coarse runs' phase with lag().

usage: bench/sloshing_phase.py RUN... [--start 3.19] [--periods 1] [--period 1.2115] [--cycles high|low]
  RUN: a coupler output directory (its probes.csv has tip_dx and tank_angle).
  Prints per run: the tip's first-harmonic amplitude (cm), the tip's lag
  behind the push (degrees, in (-180, 180]), and the tip's harmonic over half
  its range over the same periods (1 for a sinusoid, 4 / pi = 1.27 for a
  square wave: above 1 the tip dwells at its extremes, as a plate bent over
  does, whose horizontal reach grows ever slower with the load).
  --cycles CASE: also each whole cycle of the paper's metric inside the case's
  window (bench/sloshing_runs.py's cycles(), the same reading as its tables)
  that the run has reached: its peak-to-peak, crest, valley and error against
  the experiment; for a run stopped inside the window.
"""
import argparse
import math
import os
import sys

import numpy as np

from probes_csv import probes_table
from sloshing_runs import EXP, cycles

# numpy 2 renamed trapz (Debian 12 has 1.24)
TRAPZ = getattr(np, 'trapezoid', None) or np.trapz


def lag(t, tip_dx, tank_angle, t0, periods, period):
    """(lag of tip_dx's first harmonic behind -tank_angle's in degrees,
    in (-180, 180]; the tip's first-harmonic amplitude; its half range) over
    [t0, t0 + periods * period]."""
    m = (t >= t0) & (t <= t0 + periods * period)
    w = 2 * math.pi / period
    z_tip = TRAPZ(tip_dx[m] * np.exp(-1j * w * t[m]), t[m])
    z_push = TRAPZ(-tank_angle[m] * np.exp(-1j * w * t[m]), t[m])
    half_range = 0.5 * (tip_dx[m].max() - tip_dx[m].min())
    return (math.degrees(np.angle(z_push / z_tip)), 2 * abs(z_tip) / (periods * period),
            half_range)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('runs', nargs='+')
    ap.add_argument('--start', type=float, default=3.19,
                    help='s: the first cycle of the high filling\'s window by default')
    ap.add_argument('--periods', type=int, default=1)
    ap.add_argument('--period', type=float, default=1.2115,
                    help='s: the roll\'s (Eq. 55, high filling by default; low 1.646)')
    ap.add_argument('--cycles', choices=sorted(EXP),
                    help='also print the paper\'s metric cycle by cycle in this case\'s window')
    a = ap.parse_args()
    if a.periods < 1 or a.period <= 0:
        ap.error('--periods must be at least 1 and --period positive')
    status = 0
    end = a.start + a.periods * a.period
    for run in a.runs:
        try:
            p = probes_table(os.path.join(run, 'probes.csv'))
            t = p['time']
            if t[-1] < end - 0.01 * a.period or t[0] > a.start:
                raise ValueError(f'probes.csv covers {t[0]:.3f}-{t[-1]:.3f} s, not '
                                 f'{a.start}-{end:.3f} s')
            deg, tip, half = lag(t, p['tip_dx'], p['tank_angle'], a.start, a.periods, a.period)
        except (OSError, KeyError, ValueError) as e:
            print(f'{run}: {e}', file=sys.stderr, flush=True)
            status = 1
            continue
        print(f'{run}: {a.periods} period(s) from {a.start} s: tip {100 * tip:.2f} cm, lags '
              f'the push by {deg:+.1f} deg, harmonic / half range {tip / half:.3f}', flush=True)
        if a.cycles:
            e = EXP[a.cycles]
            lo, hi = e['window']
            for c0, c1, top, bottom in cycles(t, p['tip_dx'], lo, min(hi, t[-1]),
                                              smooth=e['period'] / 4):
                print(f'  cycle {c0:.3f}-{c1:.3f} s: peak to peak {100 * (top - bottom):.2f} cm '
                      f'(crest {100 * top:+.2f}, valley {100 * bottom:+.2f}), '
                      f'{100 * ((top - bottom) / e["p2p"] - 1):+.1f}% against the experiment',
                      flush=True)
    return status


if __name__ == '__main__':
    sys.exit(main())
