#!/usr/bin/python3
"""The finite-element reference of the plate at rest (bench/plate_fe.py)
checked against what is known of it, with numpy alone (dense solves, as on
CI, even where scipy is there):
  (a) a slender cantilever (L/b = 50, 2 x 100 Q9) under a uniform pressure on
      one face: the tip u_x within 0.5% of Euler-Bernoulli + Timoshenko shear
      (plane strain, nu = 0: E' = E, G = E/2, kappa = 5/6);
  (b) the self-weight buckling of that column (1 x 50 Q9): K + lambda K_G
      singular within 2% of Greenhill's lambda rho_s g b = 7.837 E I / L^3;
  (c) the thick plate at rest (dp = 3 mm) with its weight, linearised: nx = 4
      and 8 within 0.5% of each other (mesh convergence), and softer than the
      Euler-Bernoulli beam-column by a few percent (shear and the 2-D root:
      1 < FE / E-B < 1.05; converged, 1.028), which catches a lost K_G (0.86);
  (d) the closed basins (--fixed-volume, linearised, nx = 4): the levels
      conserve each basin's water (left level drop x 0.294 m = the room the
      left face gives, to 1e-12 m^2), the left one falls and the right one
      rises, and the tip falls by what beam theory gives at the new levels
      (FE ratio against E-B ratio within 0.2%; both about -2.4% at 3 mm).

usage: tests/solid/plate_fe_check.py (from the repository's root or anywhere)
Prints one line per check and 'N passed, N failed'; exits 1 when one fails."""
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, 'bench'))
import plate_fe  # noqa: E402

plate_fe.SPARSE = False   # CI has no scipy


def check(name, ok, text):
    print(f'{"ok  " if ok else "FAIL"} {name}: {text}', flush=True)
    return ok


def slender():
    fe, eb, ts = plate_fe.slender_cantilever(nx=2, slender=50)
    err = fe / ts - 1
    return check('slender cantilever', abs(err) < 0.005,
                 f'FE {fe:.6e} m, E-B + shear {ts:.6e} m ({100 * err:+.4f}%, within 0.5%); '
                 f'E-B alone {eb:.6e} m')


def buckling():
    lam, ref = plate_fe.buckling_factor(nx=1, slender=50)
    err = lam / ref - 1
    return check('self-weight buckling', abs(err) < 0.02,
                 f'lambda {lam:.6f}, Greenhill {ref:.6f} ({100 * err:+.3f}%, within 2%)')


def thick_plate():
    dp = 0.003
    u4 = plate_fe.plate_tip(dp, weight=True, nx=4)
    u8 = plate_fe.plate_tip(dp, weight=True, nx=8)
    eb = plate_fe.euler_bernoulli_tip(dp, weight=True)
    d = u8 / u4 - 1
    return [check('plate at rest, mesh convergence', abs(d) < 0.005,
                  f'nx = 4: {1e3 * u4:.5f} mm, nx = 8: {1e3 * u8:.5f} mm ({100 * d:+.4f}%, '
                  f'within 0.5%)'),
            check('plate at rest against beam theory', 1.0 < u8 / eb < 1.05,
                  f'FE / E-B = {u8 / eb:.4f} (E-B {1e3 * eb:.5f} mm; expected in (1, 1.05))')]


def fixed_volume():
    dp = 0.003
    h10, h20 = plate_fe.PLATE['h1'] - dp / 2, plate_fe.PLATE['h2'] - dp / 2
    fl = plate_fe.plate_solution(dp, weight=True, nx=4)
    fv = plate_fe.plate_solution(dp, weight=True, nx=4, fixed_volume=True)
    mesh = plate_fe.Mesh(4, 28, plate_fe.PLATE['b'], plate_fe.PLATE['L'])
    room = plate_fe.face_area(mesh, fv['u'], 0, fv['h1'])
    kept = abs((h10 - fv['h1']) * plate_fe.BASINS['w1'] - room)
    r_fe = fv['probe'] / fl['probe']
    r_eb = (plate_fe.euler_bernoulli_tip(dp, True, h1=fv['h1'], h2=fv['h2'])
            / plate_fe.euler_bernoulli_tip(dp, True))
    return [check('fixed volume: the left basin keeps its water', kept < 1e-12 and room > 0,
                  f'level {1e3 * h10:.4f} -> {1e3 * fv["h1"]:.4f} mm, room {room:.4e} m^2, '
                  f'mismatch {kept:.1e} m^2'),
            check('fixed volume: levels move the right way', fv['h1'] < h10 and fv['h2'] > h20,
                  f'right {1e3 * h20:.4f} -> {1e3 * fv["h2"]:.4f} mm'),
            check('fixed volume: tip against beam theory at the new levels', abs(r_fe / r_eb - 1) < 0.002,
                  f'FE {100 * (r_fe - 1):+.3f}%, E-B {100 * (r_eb - 1):+.3f}%')]


def main():
    t0 = time.time()
    results = [slender(), buckling()] + thick_plate() + fixed_volume()
    npass = sum(results)
    print(f'{time.time() - t0:.1f} s')
    print(f'{npass} passed, {len(results) - npass} failed')
    return 0 if all(results) else 1


if __name__ == '__main__':
    sys.exit(main())
