#!/usr/bin/python3
"""The checkpoints' cost in finished runs (docs/restart.md): for each run
directory, the checkpoints written, the size of each process's checkpoint,
and the wall time spent writing them as a share of the run's wall time (the
processes' times added: under the coupler they write one after the other
within the step).

usage: bench/checkpoint_cost.py RUN_DIR...   (prints a Markdown table)"""
import glob
import json
import os
import sys


def main():
    print('| run | particles | checkpoints | bytes per checkpoint (fluid / solid / coupler) '
          '| writing, s | wall, s | share |')
    print('|---|---|---|---|---|---|---|')
    for d in sys.argv[1:]:
        with open(os.path.join(d, 'summary.json')) as f:
            s = json.load(f)
        size = {}
        for p in ('fluid', 'solid', 'coupler'):
            files = sorted(glob.glob(os.path.join(d, 'checkpoint', p + '_*.ckpt')))
            if files:
                size[p] = os.path.getsize(files[-1])
        if 'checkpoints' in s and isinstance(s['checkpoints'], dict):  # the coupler's
            c = s['checkpoints']
            n = c['written']
            t = c['coupler_seconds'] + c.get('fluid_seconds', 0.0) + c.get('solid_seconds', 0.0)
            parts = [json.load(open(os.path.join(d, f'{p}_summary.json'))).get('particles', {})
                     for p in ('fluid',) if os.path.exists(os.path.join(d, f'{p}_summary.json'))]
        else:
            n, t = s['checkpoints'], s['checkpoint_seconds']
            parts = [s.get('particles', {})]
        npart = sum(p.get('total', 0) for p in parts if isinstance(p, dict))
        w = s['wall_seconds']
        sizes = ' / '.join(f'{size[p] / 1e6:.3g} MB' if p in size else '-'
                           for p in ('fluid', 'solid', 'coupler'))
        print(f'| {os.path.basename(os.path.normpath(d))} | {npart} | {n} | {sizes} | {t:.3f} '
              f'| {w:.1f} | {100 * t / w:.2f}% |')


if __name__ == '__main__':
    main()
