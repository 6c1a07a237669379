#!/usr/bin/python3
"""Per-step pressure measures from a run's step log (fluid.step_log).

usage: check_step_log.py RUN [--after 0.05] [--max-zero-share S]
                         [--max-mean-share M] [--max-steps-over SHARE COUNT]

RUN: a run directory with fluid_steps.csv (fluid.step_log = true). The share
of a step's PPE rows whose pressure came out at or below 0 (clamped) is
rows_at_zero / ppe_rows. --max-zero-share: the largest share after --after s
may not exceed S. --max-mean-share: their mean after --after s may not
exceed M. --max-steps-over: at most COUNT steps after --after s may
have a share above SHARE. The bands are set where the tests call this
(tests/coupler/plate.cmake), each with what it measured. Exit 0 if all hold, 1 otherwise."""
import argparse, os, sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'bench'))
from probes_csv import probes_table  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--after', type=float, default=0.05)
    ap.add_argument('--max-zero-share', type=float)
    ap.add_argument('--max-mean-share', type=float)
    ap.add_argument('--max-steps-over', type=float, nargs=2, metavar=('SHARE', 'COUNT'))
    a = ap.parse_args()
    s = probes_table(os.path.join(a.run, 'fluid_steps.csv'))
    keep = s['time'] > a.after
    if not keep.any():
        print('FAIL: no step after t = %g s in %s' % (a.after, a.run))
        return 1
    share = s['rows_at_zero'][keep] / np.maximum(s['ppe_rows'][keep], 1)
    print('%d steps after %.3g s: PPE rows at P <= 0 mean %.2f%%, max %.2f%%; PPE iterations '
          'per step %.1f' % (keep.sum(), a.after, 100 * share.mean(), 100 * share.max(),
                             s['ppe_iterations'][keep].mean()))
    ok = True
    if a.max_zero_share is not None and share.max() > a.max_zero_share:
        print('FAIL: a step has %.2f%% of its rows at P <= 0 (limit %.2f%%)'
              % (100 * share.max(), 100 * a.max_zero_share))
        ok = False
    if a.max_mean_share is not None and share.mean() > a.max_mean_share:
        print('FAIL: the steps have %.2f%% of their rows at P <= 0 on average (limit %.2f%%)'
              % (100 * share.mean(), 100 * a.max_mean_share))
        ok = False
    if a.max_steps_over is not None:
        lim, count = a.max_steps_over
        over = int(np.sum(share > lim))
        print('steps with over %.0f%% of the rows at P <= 0: %d (at most %d)' % (100 * lim, over, count))
        if over > count:
            print('FAIL: the pressure flickers from step to step')
            ok = False
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
