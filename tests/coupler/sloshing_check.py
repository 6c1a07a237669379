#!/usr/bin/python3
"""Checks a coarse coupled run of cases/sloshing_low or cases/sloshing_high.

usage: sloshing_check.py RUN_DIR --lag-band LO HI [--t-end 2.0] [--t0 0.3]
From RUN_DIR/summary.json, fluid_summary.json, solid_summary.json, probes.csv
and case_resolved.yml:
  - stable: the run finished; no fluid particle lost, escaped or put back by
    the tank guard; the plate's tip stays within 0.8 of its length and the
    solid's energy (kinetic + elastic) below 3 E I / L (twice the elastic
    energy of a tip deflected by its whole length L, plane stress);
  - motion as declared: the fluid's and the solid's tank_angle columns are
    theta(t) = amplitude sin(2 pi t / T) with T from Eq. 55 computed here
    from the case's tank width, filling and gravity, equal to
    each other (to 1e-6 deg: probes.csv keeps 9 digits), and both solvers' summaries
    report that period (to 1e-12 s);
  - the plate moves in the right phase: over the whole periods from t0 on,
    the first harmonic of tip_dx lags that of -theta (the tilted gravity's
    push along x) by an angle inside the band. A damped response to a push
    lags it by 0 (quasi-static) to about 90 degrees (at resonance, where both
    cases are forced); a mirrored response (a sign error in the frame's
    gravity) lags by about 180 degrees more.
Exit 0 if all hold, 1 otherwise; prints what it measured."""
import argparse
import json
import math
import os
import sys

import numpy as np
import yaml

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'bench'))
from probes_csv import probes_table  # noqa: E402
import sloshing_phase  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--lag-band', type=float, nargs=2, required=True)
    ap.add_argument('--t-end', type=float, default=2.0)
    ap.add_argument('--t0', type=float, default=0.3)
    a = ap.parse_args()
    bad = []
    load = lambda n: json.load(open(os.path.join(a.run, n)))  # noqa: E731
    summ, fl, so = load('summary.json'), load('fluid_summary.json'), load('solid_summary.json')
    case = yaml.safe_load(open(os.path.join(a.run, 'case_resolved.yml')))
    if summ.get('status') != 'ok' or summ.get('simulated_time', 0) < a.t_end - 1e-9:
        bad.append(f"run did not finish: {summ.get('status')}: {summ.get('message')}")
    d = probes_table(os.path.join(a.run, 'probes.csv'))
    print(f"fluid: lost {fl.get('lost_particles')}, tank guard uses {fl.get('wall_guard_uses')}, "
          f"escaped at most {d['escaped'].max():.0f}")
    if fl.get('lost_particles') or fl.get('wall_guard_uses') or d['escaped'].max() > 0:
        bad.append('fluid particles lost, escaped or put back by the tank guard')

    body = case['solid']['bodies'][0]
    t_plate = float(body['x1']) - float(body['x0'])
    L = float(body['y1'])  # free from the floor, y = 0
    EI = float(body['E']) * t_plate ** 3 / 12.0
    tip, energy = np.abs(d['tip_dx']).max(), d['solid_energy'].max()
    print(f'plate: largest |tip_dx| {tip * 100:.2f} cm (bound {0.8 * L * 100:.2f} cm), largest '
          f'energy {energy:.4g} J/m (bound 3 E I / L = {3 * EI / L:.4g} J/m)')
    if not (tip < 0.8 * L and energy < 3 * EI / L and np.isfinite(d['tip_dx']).all()):
        bad.append('the plate is not bounded')

    mo = case['motion']
    W = float(case['fluid']['tank']['width'])
    H = max(float(b['y1']) for b in case['fluid']['blocks'])
    g = math.hypot(float(case['gravity']['x']), float(case['gravity']['y']))
    T = 2 * math.pi / math.sqrt(math.pi * g / W * math.tanh(math.pi * H / W))
    amp = float(mo['amplitude'])
    want = amp * np.sin(2 * math.pi * d['time'] / T)
    e_f = np.abs(d['tank_angle'] - want).max()
    e_s = np.abs(d['solid_tank_angle'] - d['tank_angle']).max()
    T_f = fl['motion'].get('period', float('nan'))
    T_s = so['model_summary']['motion'].get('period', float('nan'))
    print(f'motion: Eq. 55 T = {T:.6f} s; fluid reports {T_f:.6f} s, solid {T_s:.6f} s; '
          f'tank_angle off {amp:g} sin(2 pi t / T) by {e_f:.2e} deg, solid off fluid by '
          f'{e_s:.2e} deg')
    if not (e_f < 1e-6 and e_s < 1e-6 and abs(T_f - T) < 1e-12 and abs(T_s - T) < 1e-12):
        bad.append('the motion is not the declared one')

    t = d['time']
    n = int((t[-1] - a.t0) / T + 1e-9)
    if n < 1:
        bad.append(f'less than a period after t0 = {a.t0} s')
    else:
        lag, tip, _ = sloshing_phase.lag(t, d['tip_dx'], d['tank_angle'], a.t0, n, T)
        print(f'phase: over {n} period(s) from {a.t0} s, tip_dx lags -theta by {lag:+.1f} deg '
              f'(band {a.lag_band[0]:g} to {a.lag_band[1]:g}); first-harmonic amplitude '
              f'{tip * 100:.2f} cm')
        if not a.lag_band[0] <= lag <= a.lag_band[1]:
            bad.append('the plate moves in the wrong phase')
    for b in bad:
        print('FAIL:', b)
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
