#!/usr/bin/python3
"""The 3D model of the sloshing cases' plate (bench/plate_3d_stiffness.py),
which sets their solid.plane_factor, checked against what is known of it,
with scipy's sparse solves where it is installed (.ci/run installs it) and
numpy's dense ones otherwise (the same figures, about four times the time),
on coarse meshes:
  (a) the element: a cantilever with nu = 0 (where the planes agree) under a
      uniform pressure, tip within 0.5% of Euler-Bernoulli + Timoshenko shear
      (1 x 1 x 10 elements: -0.11%; 2 x 1 x 20: -0.001%);
  (b) u_z = 0 is plane strain: at nu = 0.49 the strain body takes 1/(1 - nu^2)
      with the shear term, 1.3137 times the stress strip's load for the same
      small tip, within 1.5% (1 x 2 x 10: 1.304, -0.7%; 2 x 4 x 20: 1.311);
      plane stress in place of strain, or the strip's breadth taken for the
      whole plate's, fails it;
  (c) the real low plate (39 mm broad, free edges, clamped across) lies
      between the planes, linear factor in [1.10, 1.20] (1.143 here, 1.146 on
      2 x 4 x 20): the clamp's flat cross-section over about a breadth of a
      plate 1.5 breadths long;
  (d) bent to the high filling's crest, the high plate stiffens (anticlastic
      curl costs membrane energy, Ashwell 1950): its factor there over its
      linear one above 1.03 (1 x 2 x 20: 1.156 / 1.092 = 1.059).
usage: tests/solid/plate_3d_check.py
Prints one line per check and 'N passed, N failed'; exits 1 when one fails."""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, 'bench'))
import plate_3d_stiffness as p3  # noqa: E402


def check(name, ok, text):
    print(f'{"ok  " if ok else "FAIL"} {name}: {text}', flush=True)
    return ok


def element():
    L, T, E = 0.0574, p3.THICK, 6.0e6
    p = p3.Plate(L, T, (1, 1, 10), 'real', E=E, nu=0.0)
    tip = p.tip_dx(p.solve(1.0))
    eb = L ** 4 * 12 / (8 * E * T ** 3)
    ts = L ** 2 / (2 * (5 / 6) * (E / 2) * T)
    err = tip / (eb + ts) - 1
    return check('element', abs(err) < 0.005,
                 f'nu = 0 cantilever tip {tip * 1e3:.5f} mm against E-B + shear '
                 f'{(eb + ts) * 1e3:.5f} mm ({err * 100:+.2f}%, band 0.5%)')


def planes():
    nu = p3.NU_RUBBER
    L, T = 0.0574, p3.THICK
    ebs = L ** 4 * 12 / (8 * T ** 3)          # times 1/E
    ts = L ** 2 / (2 * (5 / 6) * T / (2 * (1 + nu)))
    beam = (ebs + ts) / (ebs * (1 - nu ** 2) + ts)
    _, f = p3.stiffness_factors(L, 0.0072, (1, 2, 10), linear_only=True)
    fs, fr = f['strain'][0], f['real'][0]
    ok = check('strain', abs(fs / beam - 1) < 0.015,
               f'strain body / stress strip {fs:.4f} against the beams\' {beam:.4f} '
               f'({(fs / beam - 1) * 100:+.2f}%, band 1.5%)')
    return check('low', 1.10 <= fr <= 1.20,
                 f'the real low plate {fr:.4f} times plane stress (band 1.10-1.20)') and ok


def ashwell():
    length, crest = p3.FILLINGS['high']
    _, f = p3.stiffness_factors(length, crest, (1, 2, 20), bodies=('stress', 'real'),
                                 energy=False)
    lin, cr, _ = f['real']
    return check('crest', cr / lin > 1.03,
                 f'the high plate {lin:.4f} times plane stress at a small tip, {cr:.4f} '
                 f'at {crest * 100:.2f} cm ({cr / lin:.3f}, must exceed 1.03)')


def main():
    results = [element(), planes(), ashwell()]
    print(f'{sum(results)} passed, {len(results) - sum(results)} failed')
    return 0 if all(results) else 1


if __name__ == '__main__':
    sys.exit(main())
