#!/usr/bin/python3
"""The sloshing plates alone (no oil, a fixed tank): the solid's bending against
Euler-Bernoulli in plane stress and plane strain, per model and dp.

The plate of cases/sloshing_{low,high} (4 mm thick, rho 1100, E 6 MPa, nu 0.49,
clamped below the floor) is loaded by a small sideways gravity, applied at once
(gravity.x = -0.981 m/s^2, 1/10 g: the tip moves 2-3 mm, 5% of the low plate's
length, so the response stays linear). Then the tip swings about the static
deflection w = q L^4 / (8 E' I) (q = rho t a, I = t^3 / 12 per metre) with the
first cantilever frequency f = 1.875^2 / (2 pi) sqrt(E' I / (rho t L^4)),
E' = E (plane stress) or E / (1 - nu^2) (plane strain: 1.32 E at nu = 0.49).
Measured: the mean of tip_dx over the run (whole periods: the static
deflection) and its period from the zero crossings of tip_dx - mean. L is the
free length the lattice gives at each dp (the rows above y = 0).

usage: bench/sloshing_plate_alone.py [--dp 0.002 0.001 0.0008] [--out DIR]
       [--plot docs/img/sloshing_plate_alone.png] [--set KEY=VALUE ...] > table.md
"""
import argparse
import math
import os
import subprocess
import sys


from probes_csv import probes_table

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOLID = os.path.join(ROOT, 'build', 'bin', 'solid_solver')
E, NU, RHO, T, A = 6.0e6, 0.49, 1100.0, 0.004, 0.981
CASES = {'low': 0.0574, 'high': 0.1148}


def theory(L, plane):
    Ep = E if plane == 'stress' else E / (1.0 - NU * NU)
    I = T ** 3 / 12.0
    w = RHO * T * A * L ** 4 / (8.0 * Ep * I)
    f = 1.875104 ** 2 / (2.0 * math.pi) * math.sqrt(Ep * I / (RHO * T * L ** 4))
    return w, f


def free_length(H, dp):
    # rows of the body from y0 = -0.004 to H, minus the 4 mm below the floor
    return math.floor((H + 0.004) / dp + 1e-6) * dp - 0.004


def measure(path):
    d = probes_table(path)
    t, x = d['time'], d['tip_dx']
    m = x.mean()
    s = x - m
    up = [t[k] - s[k] * (t[k + 1] - t[k]) / (s[k + 1] - s[k])
          for k in range(len(s) - 1) if s[k] < 0 <= s[k + 1]]
    period = (up[-1] - up[0]) / (len(up) - 1) if len(up) > 1 else float('nan')
    # mean over whole periods, from the first to the last up-crossing
    if len(up) > 1:
        k = (t >= up[0]) & (t <= up[-1])
        m = x[k].mean()
    return m, period


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--dp', type=float, nargs='+', default=[0.002, 0.001, 0.0008])
    ap.add_argument('--models', nargs='+', default=['mps', 'tlsph', 'tlsph_linear'])
    ap.add_argument('--out', default='runs/plate_alone')
    ap.add_argument('--courant', default='0.75')
    ap.add_argument('--plot', default=None)
    ap.add_argument('--set', action='append', default=[], metavar='KEY=VALUE',
                    help='passed to the solid (e.g. solid.refine=2), after the script\'s own')
    a = ap.parse_args()
    rows = []
    for case, H in CASES.items():
        for plane in ('stress', 'strain'):
            for dp in a.dp:
                L = free_length(H, dp)
                w0, f0 = theory(L, plane)
                for model in a.models:
                    out = os.path.join(a.out, f'{case}_{plane}_{model}_{dp * 1e3:g}')
                    # six periods of the stiffer theory
                    end = 6.0 / f0
                    # tlsph: the cases' quadratic correction; tlsph_linear: the default one
                    extra = (['--set', 'solid.tlsph.correction=linear']
                             if model == 'tlsph_linear' else [])
                    cmd = [SOLID, os.path.join(ROOT, 'cases', f'sloshing_{case}', 'case.yml'),
                           '--out', out, '--model', model.split('_')[0], '--quiet'] + extra + [
                           '--set', f'dp={dp}',
                           '--set', f'end_time={end:.4f}', '--set', 'output.interval=0',
                           '--set', 'output.probe_interval=0.0002', '--set', 'motion.kind=none',
                           '--set', f'gravity.x={-A}', '--set', 'gravity.y=0',
                           '--set', f'solid.plane={plane}', '--set', f'solid.courant={a.courant}',
                           # the 2D planes themselves, against Euler-Bernoulli with E or E':
                           # the cases' 3D factor (docs/sloshing.md) left out
                           '--set', 'solid.plane_factor=1']
                    for kv in a.set:
                        cmd += ['--set', kv]
                    r = subprocess.run(cmd, capture_output=True, text=True)
                    if r.returncode:
                        rows.append((case, plane, dp, model, L, w0, f0, None, None, r.stderr.strip()))
                        continue
                    w, period = measure(os.path.join(out, 'probes.csv'))
                    rows.append((case, plane, dp, model, L, w0, f0, -w, 1.0 / period, ''))
                    print(f'{case} {plane} {model} dp {dp * 1e3:g} mm: static {-w * 1e3:.3f} mm '
                          f'(E-B {w0 * 1e3:.3f}), f {1 / period:.3f} Hz (E-B {f0:.3f})',
                          file=sys.stderr)
    print('| plate | plane | dp (particles thick) | model | free length | static tip (E-B) | '
          'error | frequency (E-B) | error |')
    print('|---|---|---|---|---|---|---|---|---|')
    for case, plane, dp, model, L, w0, f0, w, f, msg in rows:
        head = (f'| {case} | {plane} | {dp * 1e3:g} mm ({round(T / dp)}) | {model} | '
                f'{L * 1e3:.1f} mm |')
        if w is None:
            print(head + f' failed: {msg} | | | |')
            continue
        print(head + f' {w * 1e3:.3f} mm ({w0 * 1e3:.3f}) | {100 * (w / w0 - 1):+.1f}% | '
              f'{f:.2f} Hz ({f0:.2f}) | {100 * (f / f0 - 1):+.1f}% |')
    if a.plot:
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt
        fig, axs = plt.subplots(1, 2, figsize=(10, 4))
        for ax, case in zip(axs, CASES):
            for plane, mk in (('stress', 'o'), ('strain', 's')):
                for model, ls in (('mps', '-'), ('tlsph', '--'), ('tlsph_linear', ':')):
                    sel = [r for r in rows if r[0] == case and r[1] == plane and r[3] == model
                           and r[7] is not None]
                    if sel:
                        ax.plot([r[2] * 1e3 for r in sel], [r[7] / r[5] for r in sel], ls,
                                marker=mk, label=f'{model}, plane {plane}')
            ax.axhline(1.0, color='k', lw=0.8)
            ax.set_xlabel('dp (mm)')
            ax.set_ylabel('static tip / Euler-Bernoulli')
            ax.set_title(f'{case} plate ({CASES[case] * 1e3:g} mm), alone')
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)


if __name__ == '__main__':
    main()
