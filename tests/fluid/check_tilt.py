#!/usr/bin/python3
"""Checks a run of tests/fluid/tilt_fixed.yml: a tank held at a fixed tilt.

usage: check_tilt.py RUN_DIR [--angle 5] [--pivot 0.15 0] [--rho 1000] [--g 9.81]
                     [--t-end 2.0]
The solver works in the tank's frame; the last snapshot's particles are turned
into the lab frame (x_lab = pivot + R(angle) (x - pivot)) and:
  - the run finished, no particle escaped, the water is still (max speed at
    the end below 1% of sqrt(g h));
  - the free surface (the free-surface fluid particles away from the walls'
    menisci, x in the middle 80%) is level in the lab: its fitted slope is
    below a tenth of the tank's tilt tan(angle) (a fluid that ignored the
    tilt keeps its surface level in the tank: slope tan(angle) in the lab);
    and the probes level_left / level_right (tank frame) differ by
    (W - dp) tan(angle) within one spacing;
  - the pressure is hydrostatic below that surface: for fluid particles more
    than 3 dp deep, p = rho g d within 3% on average (the hydrostatic case's
    band, docs/fluid.md: the surface sits at the top particles' centres, dp/2
    below the water line, which alone makes -1.7% at the bottom there) and
    within 10% for 95% of them (single-particle pressure noise).
Exit 0 if all hold, 1 otherwise; prints what it measured."""
import argparse
import glob
import math
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'bench'))
from probes_csv import finished, probes_table  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--angle', type=float, default=5.0)
    ap.add_argument('--pivot', type=float, nargs=2, default=[0.15, 0.0])
    ap.add_argument('--width', type=float, default=0.3)
    ap.add_argument('--rho', type=float, default=1000.0)
    ap.add_argument('--g', type=float, default=9.81)
    ap.add_argument('--depth', type=float, default=0.06)
    ap.add_argument('--t-end', type=float, default=2.0)
    a = ap.parse_args()
    bad = []
    summ, why = finished(a.run, a.t_end)
    if why:
        bad.append(why)
    snaps = sorted(glob.glob(os.path.join(a.run, 'fluid_*.h5')))
    if not snaps:
        print('FAIL: no snapshot')
        sys.exit(1)
    with h5py.File(snaps[-1], 'r') as f:
        t = float(f.attrs['time'])
        x = f['particles/position'][:, :2]  # (x, y, 0) in the files
        p = f['particles/pressure'][:]
        typ = f['particles/type'][:]
        surf = f['particles/free_surface'][:]
        cfg = f['config'][()]
    dp = float(next(l.split(':')[1] for l in cfg.decode().splitlines() if l.startswith('dp:')))
    if t < a.t_end - 1e-9:
        bad.append(f'last snapshot at t = {t} s, expected {a.t_end}')
    th = math.radians(a.angle)
    c, s = math.cos(th), math.sin(th)
    r = x - np.array(a.pivot)
    xl = np.column_stack([a.pivot[0] + c * r[:, 0] - s * r[:, 1],
                          a.pivot[1] + s * r[:, 0] + c * r[:, 1]])
    fluid = typ == 0
    # the middle 80% of the tank (its walls' menisci left out), in tank x
    mid = (x[:, 0] > 0.1 * a.width) & (x[:, 0] < 0.9 * a.width)
    top = fluid & (surf == 1) & mid
    if top.sum() < 10:
        bad.append(f'only {top.sum()} free-surface particles in the middle of the tank')
        slope, icpt = float('nan'), float('nan')
    else:
        slope, icpt = np.polyfit(xl[top, 0], xl[top, 1], 1)
    lim = 0.1 * math.tan(th)
    print(f'free surface in the lab frame at t = {t} s: slope {slope:+.5f} from {top.sum()} '
          f'particles (tank tilt tan = {math.tan(th):.5f}; limit |slope| < {lim:.5f})')
    if not abs(slope) < lim:
        bad.append('the surface is not level in the lab frame')
    # probes in the tank frame
    d = probes_table(os.path.join(a.run, 'probes.csv'))
    dl = d['level_left'][-1] - d['level_right'][-1]
    want = (a.width - dp) * math.tan(th)
    print(f'level_left - level_right (tank frame) {dl * 1e3:.2f} mm, expected (W - dp) tan = '
          f'{want * 1e3:.2f} mm (within dp = {dp * 1e3:g} mm)')
    if not abs(dl - want) <= dp:
        bad.append('tank-frame level difference off')
    vend = d['max_speed'][-1]
    vlim = 0.01 * math.sqrt(a.g * a.depth)
    print(f'max speed at the end {vend:.5f} m/s (limit {vlim:.5f})')
    if not vend < vlim:
        bad.append('the water is not still at the end')
    # hydrostatic pressure below the fitted surface line
    depth = icpt + slope * xl[:, 0] - xl[:, 1]
    deep = fluid & (depth > 3 * dp)
    ratio = p[deep] / (a.rho * a.g * depth[deep])
    mean = float(ratio.mean()) if deep.any() else float('nan')
    within = float(np.mean(np.abs(ratio - 1.0) < 0.10)) if deep.any() else 0.0
    print(f'pressure / rho g depth over {deep.sum()} particles deeper than 3 dp: mean '
          f'{mean:.4f}, {100 * within:.1f}% within 10%')
    if not abs(mean - 1.0) < 0.03:
        bad.append('mean pressure not hydrostatic within 3%')
    if not within >= 0.95:
        bad.append('fewer than 95% of the particles within 10% of hydrostatic')
    if summ.get('wall_guard_uses', 0) or summ.get('lost_particles', 0):
        bad.append(f"tank guard uses {summ.get('wall_guard_uses')}, lost "
                   f"{summ.get('lost_particles')}")
    for b in bad:
        print('FAIL:', b)
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
