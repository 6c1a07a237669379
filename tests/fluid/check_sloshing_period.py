#!/usr/bin/python3
"""Checks a run of tests/fluid/sloshing_free.yml: the first sloshing mode's
period against Eq. 55.

usage: check_sloshing_period.py RUN_DIR [--length 0.609] [--depth 0.0574]
                                [--angle 1.0] [--tol 0.02] [--t-end 5.2]
The tank is held tilted from t = 0 with its oil level in the tank, so the oil
sloshes about the level (in the lab) surface. The antisymmetric signal
level_left - level_right (tank frame, m) is fitted over the whole run with
  s(t) = c + A exp(-gamma t) sin(2 pi t / T + phi)
(least squares; T and gamma by a grid refined twice). Checks:
  - the run finished, no particle escaped the tank, no tank guard use;
  - T within tol (2%) of Eq. 55, T = 2 pi (pi g / L tanh(pi H_L / L))^(-1/2).
    Eq. 55 is linear theory; the discrete depth (the surface at the top
    particles' centres, 19 layers here, H_L rounded down to the lattice)
    lengthens the period by about 1.5% by the same formula, the amplitude
    (9% of the depth) shifts it by well under 1%;
  - the mean c (the tilted equilibrium seen from the tank) within 15% of
    (W - dp) tan(angle): the tilt's sign and size reach the fluid;
  - A between 0.6 and 1.0 of c: a linear initial surface projects 8/pi^2 =
    81% on the first mode (the rest on the odd higher ones).
Exit 0 if all hold, 1 otherwise; prints what it measured."""
import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'bench'))
from probes_csv import finished, probes_table  # noqa: E402


def fit(t, s, T0):
    """Least-squares damped sinusoid plus constant; returns (T, gamma, A, c, rms)."""
    def solve(T, g):
        w = 2 * math.pi / T
        e = np.exp(-g * t)
        M = np.column_stack([e * np.sin(w * t), e * np.cos(w * t), np.ones_like(t)])
        coef = np.linalg.lstsq(M, s, rcond=None)[0]
        return float(((M @ coef - s) ** 2).sum()), coef
    best = None
    Ts, gs = np.linspace(0.7 * T0, 1.3 * T0, 121), np.linspace(0.0, 2.0, 41)
    for _ in range(3):
        for T in Ts:
            for g in gs:
                r, coef = solve(T, g)
                if best is None or r < best[0]:
                    best = (r, T, g, coef)
        dT, dg = Ts[1] - Ts[0], gs[1] - gs[0]
        Ts = np.linspace(best[1] - 2 * dT, best[1] + 2 * dT, 41)
        gs = np.linspace(max(0.0, best[2] - 2 * dg), best[2] + 2 * dg, 21)
    r, T, g, coef = best
    return T, g, math.hypot(coef[0], coef[1]), coef[2], math.sqrt(r / len(t))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--length', type=float, default=0.609)
    ap.add_argument('--depth', type=float, default=0.0574)
    ap.add_argument('--angle', type=float, default=1.0)
    ap.add_argument('--dp', type=float, default=0.003)
    ap.add_argument('--g', type=float, default=9.81)
    ap.add_argument('--tol', type=float, default=0.02)
    ap.add_argument('--t-end', type=float, default=5.2)
    a = ap.parse_args()
    bad = []
    summ, why = finished(a.run, a.t_end)
    if why:
        bad.append(why)
    if summ.get('wall_guard_uses', 0) or summ.get('lost_particles', 0):
        bad.append(f"tank guard uses {summ.get('wall_guard_uses')}, lost "
                   f"{summ.get('lost_particles')}")
    d = probes_table(os.path.join(a.run, 'probes.csv'))
    if d['escaped'].max() if 'escaped' in d.dtype.names else 0:
        bad.append('particles escaped the tank')
    L, H = a.length, a.depth
    T55 = 2 * math.pi / math.sqrt(math.pi * a.g / L * math.tanh(math.pi * H / L))
    t, s = d['time'], d['level_left'] - d['level_right']
    T, g, A, c, rms = fit(t, s, T55)
    c_want = (L - a.dp) * math.tan(math.radians(a.angle))
    print(f'first mode: period {T:.4f} s against Eq. 55 {T55:.4f} s ({100 * (T / T55 - 1):+.2f}%, '
          f'tolerance {100 * a.tol:g}%); decay {g:.3f} 1/s; fit rms {rms * 1e3:.2f} mm')
    print(f'level difference: mean {c * 1e3:.2f} mm (tilted equilibrium (W - dp) tan = '
          f'{c_want * 1e3:.2f} mm), first-mode amplitude {A * 1e3:.2f} mm ({A / c_want:.2f} of it)')
    if not abs(T / T55 - 1.0) <= a.tol:
        bad.append('period off Eq. 55')
    if not abs(c / c_want - 1.0) <= 0.15:
        bad.append('the tilted equilibrium is off')
    if not 0.6 <= A / c_want <= 1.0:
        bad.append('first-mode amplitude off')
    for b in bad:
        print('FAIL:', b)
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
