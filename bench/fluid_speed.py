#!/usr/bin/python3
"""Fluid solver speed: time per particle-step and its split, as N grows.

usage: bench/fluid_speed.py [--bin build/bin] [--threads 1,2] [--out docs/fluid_speed.md]
                            [--sizes DP,DP,...] [--repeat K or K,K,...]
Runs the dam break (cases/dambreak) at spacings that give about 6k, 20k, 80k
and 290k particles (fluid + wall + dummy) over the first 0.08 s of simulated
time, once per thread count, and tabulates ns per particle-step by phase from
each run's summary.json; each of these rows is the fastest of --repeat runs (3:
a run of 80 steps at 6k particles varies by 10-15% from run to run here; a
list gives each size its own count, e.g. 3,3,3,1 for one run of the 290k rows,
which vary less and take a quarter of an hour each on one thread). Then
the growth of the cost per particle-step from size to size, against N log N's.
Also times the paper's coarsest dam break (dp = 3 mm, 4,656
fluid particles) over 1 s of simulated time, with the case's time step and
with the solver's defaults. Run it on a quiet machine: about 28 minutes on
2 cores, most of it the 290k runs (--sizes 0.0035,0.0018,0.0008 leaves them out)."""
import argparse, os, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'bench'))
from bench_doc import host_line, write_keeping_notes  # noqa: E402
from dambreak_compare import run_dambreak  # noqa: E402


def run(binary, dp, end, threads, extra=()):
    _, s, ok, cmd = run_dambreak(binary, threads, [f'dp={dp}', f'end_time={end}', *extra],
                                 prefix='fspeed_')
    s['failed'] = not ok
    return s, cmd


def case_time_step():
    """The dam-break case's time-step keys, read from its file."""
    import re
    with open(os.path.join(ROOT, 'cases/dambreak/case.yml')) as f:
        text = f.read()
    c = re.search(r'^\s+courant:\s*([0-9.]+)', text, re.M)
    k = re.search(r'^\s+droplet_neighbours:\s*([0-9]+)', text, re.M)
    parts = [f'Courant {c.group(1) if c else "0.2"}']
    if k and int(k.group(1)) > 0:
        parts.append(f'droplets of fewer than {k.group(1)} neighbours held to one spacing '
                     'per step')
    return ', '.join(parts)


def growth_table(per_size):
    """Markdown lines: the cost per particle-step of each size over the
    previous size's, next to N log N's (log N2 / log N1 per particle)."""
    import math
    out = ['', 'Growth of the cost per particle-step from each size to the next, against '
           'N log N (whose cost per particle-step grows as log N):', '',
           '| from N | to N | threads | measured | N log N |', '|---|---|---|---|---|']
    for t, rows in per_size.items():
        # each size to the next, then the smallest to the largest
        pairs = list(zip(rows, rows[1:])) + ([(rows[0], rows[-1])] if len(rows) > 2 else [])
        for (n1, c1), (n2, c2) in pairs:
            out.append(f'| {n1} | {n2} | {t} | {c2 / c1:.2f}x | '
                       f'{math.log(n2) / math.log(n1):.2f}x |')
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--bin', default=os.path.join(ROOT, 'build', 'bin'))
    ap.add_argument('--threads', default='1,2')
    ap.add_argument('--out', default=os.path.join(ROOT, 'docs', 'fluid_speed.md'))
    ap.add_argument('--sizes', default='0.0035,0.0018,0.0008,0.0004')
    ap.add_argument('--repeat', default='3',
                    help='runs per row, the fastest kept: one count, or one per size')
    args = ap.parse_args()
    try:
        sizes = [float(x) for x in args.sizes.split(',')]
    except ValueError:
        ap.error(f'--sizes {args.sizes}: give spacings in metres, e.g. 0.0035,0.0018')
    try:
        repeats = [int(x) for x in args.repeat.split(',')]
    except ValueError:
        ap.error(f'--repeat {args.repeat}: give one count >= 1, or one per size')
    if len(repeats) == 1:
        repeats *= len(sizes)
    if len(repeats) != len(sizes) or min(repeats) < 1:
        ap.error(f'--repeat {args.repeat}: give one count >= 1, or one per size ({len(sizes)})')
    threads = [int(t) for t in args.threads.split(',')]
    phases = ['neighbours', 'predict', 'density', 'ppe_assemble', 'ppe_solve', 'correct', 'other']
    lines = ['# Fluid solver speed', '',
             'Reproduce: `bench/fluid_speed.py` (Release build, quiet 2-core machine).', '',
             'Dam break (`cases/dambreak`) over a short simulated time; N counts fluid, wall and '
             'dummy particles; ns per particle-step by phase (from `summary.json`), of the '
             f'fastest of {" / ".join(map(str, repeats))} runs (per size).', '',
             '| dp (mm) | N | threads | steps | PPE iters/step | ' + ' | '.join(phases) +
             ' | total ns/particle-step |',
             '|' + '---|' * (len(phases) + 6)]
    per_size = {t: [] for t in threads}   # (N, ns per particle-step) per thread count
    for dp, repeat in zip(sizes, repeats):
        # the same window for every size: the first steps from rest take the
        # 1 ms step cap and harder PPEs, so a shorter window would not compare
        end = 0.08
        for t in threads:
            s = min((run(args.bin, dp, end, t)[0] for _ in range(repeat)),
                    key=lambda r: r['ns_per_particle_step'])
            n = s['particles']['total']
            ps = s['steps'] * n
            cells = [f"{1e9 * s['phase_seconds'][p] / ps:.0f}" for p in phases]
            per_size[t].append((n, s['ns_per_particle_step']))
            lines.append(f"| {dp * 1e3:.2f} | {n} | {t} | {s['steps']} | "
                         f"{s['ppe_iterations_per_step']:.1f} | " + ' | '.join(cells) +
                         f" | {s['ns_per_particle_step']:.0f} |")
    lines[4:4] = [host_line(s), '']   # the machine, after 'Reproduce: ...'
    lines += growth_table(per_size)
    lines += ['', '## The paper\'s coarsest dam break: 1 s of simulated time', '',
              f'Time step: the case\'s ({case_time_step()}), and the solver\'s defaults '
              '(Courant 0.2, droplets counted) for comparison.', '',
              '| dp (mm) | fluid particles | time step | threads | steps | PPE iters/step | '
              'wall s | ns/particle-step |',
              '|---|---|---|---|---|---|---|---|']
    defaults = ('fluid.courant=0.2', 'fluid.droplet_neighbours=0')
    cmds = []
    for label, extra, ts in (('case', (), threads), ('defaults', defaults, threads[-1:])):
        for t in ts:
            s, cmd = run(args.bin, 0.003, 1.0, t, extra)
            reached = (f" (stopped at t = {s['simulated_time']:.3f} s: {s['message']})"
                       if s['failed'] else '')
            lines.append(f"| 3.00 | {s['particles']['fluid']} | {label} | {t} | "
                         f"{s['steps']}{reached} | {s['ppe_iterations_per_step']:.1f} | "
                         f"{s['wall_seconds']:.1f} | {s['ns_per_particle_step']:.0f} |")
            cmds.append(f'OMP_NUM_THREADS={t} {cmd}')
    lines += ['', 'Commands (case, then defaults, on the last thread count): ' +
              '; '.join(f'`{c}`' for c in (cmds[-2], cmds[-1])), '']
    # the hand-written reading of the figures (from "## Reading it" on) is kept
    lines = write_keeping_notes(args.out, lines, '## Reading it')
    print('\n'.join(lines))


if __name__ == '__main__':
    main()
