#!/usr/bin/python3
"""The same dam break run by PySPH, measured here: speed against error.

usage: bench/pysph_dambreak.py [--cols 18,36,73] [--threads 2] [--scheme wcsph]
                               [--bin build/bin] [--keep DIR]

PySPH (Debian's python3-pysph 1.0~b1: `apt-get install python3-pysph`) ships
the Koshizuka & Oka dam break as pysph.examples.dam_break_2d: a column 1 m
wide and 2 m high in a 4 m tank, weakly compressible SPH (c0 = 10 sqrt(2 g H),
Wendland quintic kernel, h = 1.3 dx, PEC integrator with adaptive steps). It
is run unchanged except for the spacing (the column is `cols` particles wide,
as ours is floor(0.146 / dp): 18, 36, 73 at dp = 8, 4, 2 mm; its block has
1/dx + 1 columns, so dx = 1/(cols - 1)), to T = 3 (the
end of the Martin & Moyce table we compare with) on the same number of OpenMP
threads. Next to it, the fluid_solver at the matching dp.

Both are scored the same way (bench/dambreak_compare.py): the front is the
largest x of the fluid in the two lowest layers plus half a spacing from the
wall's face, the height the highest particle of the first column plus half a
spacing, non-dimensionalised by the column's own width (cols spacings: ours
0.144 m at 4 mm, PySPH's 1 + dx from x = dx/2, its wall particles at x = 0
and y = 0 with their faces half a spacing in). Wall time: PySPH's own
"Run took" (the time loop, without its Cython compilation and set-up); ours
from summary.json (the same: the time loop without set-up). Prints one
markdown row per code and spacing."""
import argparse, glob, math, os, re, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'bench'))
import dambreak_compare as dc  # noqa: E402

PY = '/usr/bin/python3'  # Debian's, where python3-pysph lives
G = 9.81


def pysph_probes(outdir, dx, run_dir):
    """Writes run_dir/probes.csv (time, front, height) from PySPH's output;
    returns the column width a and the last output's step count."""
    from pysph.solver.utils import load
    files = sorted(glob.glob(os.path.join(outdir, 'dam_break_2d_*.hdf5')),
                   key=lambda f: int(re.findall(r'_(\d+)\.hdf5$', f)[0]))
    rows, a = [], None
    face = 0.5 * dx  # wall particles at x = 0 and y = 0: faces half a spacing in
    for f in files:
        d = load(f)
        fl = d['arrays']['fluid']
        x, y = fl.get('x'), fl.get('y')
        if a is None:
            a = x.max() - x.min() + dx  # the column's width at t = 0
            x0 = x.min()
        low = y < y.min() + 2.0 * dx
        front = x[low].max() + 0.5 * dx - face
        col = x < x0 + dx
        height = (y[col].max() + 0.5 * dx - face) if col.any() else 0.0
        rows.append((d['solver_data']['t'], front, height))
        count = d['solver_data']['count']
    os.makedirs(run_dir, exist_ok=True)
    with open(os.path.join(run_dir, 'probes.csv'), 'w') as out:
        out.write('time,front,height\n')
        for r in rows:
            out.write('%.9g,%.9g,%.9g\n' % r)
    return a, count


def run_pysph(cols, threads, scheme, keep, nnps):
    dx = 1.0 / (cols - 1)  # the block has 1/dx + 1 columns
    a_nom = 1.0
    tf = 3.0 / math.sqrt(2 * G / a_nom) * 1.05
    outdir = tempfile.mkdtemp(prefix='pysph_db_', dir=keep)
    cmd = [PY, '-m', 'pysph.examples.dam_break_2d', '--dx', repr(dx), '--tf', '%.4f' % tf,
           '-d', outdir, '--openmp', '--pfreq', '100', '-q', '--scheme', scheme, '--nnps', nnps]
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if p.returncode != 0:
        why = 'signal %d' % -p.returncode if p.returncode < 0 else 'exit %d' % p.returncode
        return dict(failed=why, cmd=' '.join(cmd))
    log = open(os.path.join(outdir, 'dam_break_2d.log')).read()
    took = float(re.findall(r'Run took: ([0-9.]+) secs', log)[-1])
    nf = int(re.findall(r'fluid: (\d+)', log)[0])
    ntot = int(re.findall(r'Total: (\d+)', log)[0])
    probes = os.path.join(outdir, 'probes')
    a, steps = pysph_probes(outdir, dx, probes)
    return dict(a=a, wall=took, fluid=nf, total=ntot, steps=steps, run=probes, cmd=' '.join(cmd))


def run_ours(dp, threads, binary):
    out, s, ok, cmd = dc.run_dambreak(binary, threads, [f'dp={dp}', 'end_time=0.27'],
                                      prefix='db_ours_')
    if not ok:
        sys.exit(f'fluid_solver failed: {s["message"]}')
    a = math.floor(0.146 / dp + 1e-9) * dp
    return dict(a=a, wall=s['step_seconds'], fluid=s['particles']['fluid'],
                total=s['particles']['total'], steps=s['steps'], run=out, cmd=cmd)


def row(code, label, r):
    if 'failed' in r:
        return f"| {code} | {label} | failed ({r['failed']}) | | | | |"
    c = dc.compare(r['run'], r['a'], 3.0)
    return (f"| {code} | {label} | {r['fluid']} / {r['total']} | {r['steps'] or '?'} | "
            f"{r['wall']:.1f} | {100 * c['front_max_rel_err']:.1f}% / "
            f"{100 * c['front_mean_rel_err']:.1f}% | {100 * c['height_max_rel_err']:.1f}% / "
            f"{100 * c['height_mean_rel_err']:.1f}% |")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--cols', default='18,36,73')
    ap.add_argument('--threads', type=int, default=2)
    ap.add_argument('--scheme', default='wcsph')
    ap.add_argument('--bin', default=os.path.join(ROOT, 'build', 'bin'))
    ap.add_argument('--keep', default=None, help='directory for PySPH output')
    ap.add_argument('--nnps', default='ll', help="PySPH's neighbour search (its default: ll)")
    a = ap.parse_args()
    print('| code | column (particles across) | fluid / all particles | steps | wall s to T = 3 | '
          'front max / mean error | height max / mean error |')
    print('|---|---|---|---|---|---|---|')
    cmds = []
    for cols in (int(c) for c in a.cols.split(',')):
        dp = {18: 0.008, 36: 0.004, 73: 0.002}.get(cols, 0.146 / cols)
        ours = run_ours(dp, a.threads, a.bin)
        print(row('fluid_solver', f'{cols} (dp = {dp * 1e3:g} mm)', ours), flush=True)
        ps = run_pysph(cols, a.threads, a.scheme, a.keep, a.nnps)
        print(row(f'PySPH {a.scheme}', f'{cols} (dx = 1/{cols - 1} m)', ps), flush=True)
        cmds += [ours['cmd'], ps['cmd']]
    print('\nCommands:\n' + '\n'.join(f'- `{c}`' for c in cmds))


if __name__ == '__main__':
    main()
