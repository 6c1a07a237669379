#!/usr/bin/python3
"""Dam break: what the time step (Courant number, droplet rule) costs and buys.

usage: bench/dambreak_time_step.py [--bin build/bin] [--threads 2]
           [--courants 0.2,0.3,0.4,0.5,0.6] [--out docs/dambreak_time_step.md]
For each Courant number, with droplets counted (fluid.droplet_neighbours=0)
and with droplets of fewer than 3 neighbours held to one spacing per step
(=3): the 4 mm run to T = 3 against Martin & Moyce (front and height errors,
bench/dambreak_compare.py) and the 3 mm run to 1 s (steps, wall time, whether
it finished). Writes a markdown table. Run it on a quiet machine."""
import argparse, os, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'bench'))
from bench_doc import host_line, write_keeping_notes  # noqa: E402
from dambreak_compare import compare, run_dambreak  # noqa: E402


def run(binary, threads, sets):
    out, summ, ok, _ = run_dambreak(binary, threads, sets, prefix='dbts_', quiet_stderr=True)
    return out, summ, ok


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--bin', default=os.path.join(ROOT, 'build', 'bin'))
    ap.add_argument('--threads', type=int, default=2)
    ap.add_argument('--courants', default='0.2,0.3,0.4,0.5,0.6')
    ap.add_argument('--out', default=os.path.join(ROOT, 'docs', 'dambreak_time_step.md'))
    a = ap.parse_args()
    lines = ['# Dam break: the time step', '',
             f'Reproduce: `bench/dambreak_time_step.py` ({a.threads} threads, quiet machine). '
             'Front and height: max / mean relative error against Martin & Moyce at the '
             'table points up to T = 3 (4 mm). 3 mm to 1 s: steps and wall time.', '',
             '| Courant | droplets (k) | 4 mm front max / mean | 4 mm height max / mean | '
             '3 mm to 1 s: steps | wall s | PPE iters/step | guard uses |',
             '|---|---|---|---|---|---|---|---|']
    for c in (float(x) for x in a.courants.split(',')):
        for k in (0, 3):
            base = [f'fluid.courant={c}', f'fluid.droplet_neighbours={k}']
            out4, s4, ok4 = run(a.bin, a.threads, base + ['dp=0.004', 'end_time=0.27'])
            if ok4:
                r = compare(out4)
                fe = [abs(e[3]) for e in r['front']]
                he = [abs(e[3]) for e in r['height']]
                acc = (f'{100 * max(fe):.1f}% / {100 * sum(fe) / len(fe):.1f}% | '
                       f'{100 * max(he):.1f}% / {100 * sum(he) / len(he):.1f}%')
            else:
                acc = f'failed: {s4["message"]} | -'
            _, s3, ok3 = run(a.bin, a.threads, base + ['dp=0.003', 'end_time=1.0'])
            steps = (f'{s3["steps"]}' if ok3 else
                     f'{s3["steps"]}, stopped at t = {s3["simulated_time"]:.3f} s: '
                     f'{s3["message"]}')
            lines.append(f'| {c:g} | {k} | {acc} | {steps} | {s3["wall_seconds"]:.1f} | '
                         f'{s3["ppe_iterations_per_step"]:.1f} | {s3["wall_guard_uses"]} |')
            print(lines[-1], flush=True)
    lines[2:2] = [host_line(s3), '']   # the machine, under the title
    lines.append('')
    # the hand-written reading (from "Command per row" on) is kept
    write_keeping_notes(a.out, lines, 'Command per row')


if __name__ == '__main__':
    main()
