#!/usr/bin/python3
"""The elastic gate (cases/elastic_gate) alone under still water, static,
against Timoshenko beam theory (issue 18, docs/hard_cases.md section 3a):
a problem with a known answer for the solid models.

usage: gate_static_check.py BUILD_DIR MODEL DP LO HI

Runs build/bench/solid_static_load on the gate with the water's load scaled
by 0.01 (a 0.4 mm tip: linear) and passes if tip / Timoshenko lies in
[LO, HI]. The beam theory is bench/hard_cases.py's (plane strain, Cowper's
shear coefficient, at the probe's height). Exit 0 pass, 1 fail."""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, '..', '..'))
sys.path.insert(0, os.path.join(ROOT, 'bench'))
from hard_cases import GATE, timoshenko_tip  # noqa: E402

SCALE = 0.01


def main():
    build, model, dp, lo, hi = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), \
        float(sys.argv[5])
    cmd = [os.path.join(build, 'bench', 'solid_static_load'),
           os.path.join(ROOT, 'cases', 'elastic_gate', 'case.yml'), '--body', 'gate',
           '--water-level', str(GATE['H']), '--model', model, '--load-scale', str(SCALE),
           '--set', f'dp={dp}', '--max-time', '3']
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=240)
    if p.returncode not in (0, 1) or not p.stdout.strip():
        print(f'FAIL  solid_static_load exited {p.returncode}: {p.stderr.strip()}')
        return 1
    r = json.loads(p.stdout.strip().splitlines()[-1])
    eb, ti = timoshenko_tip(dp, SCALE)
    tip = r['probes']['tip_dx']
    ok = r['settled'] and lo <= tip / ti <= hi
    print(('ok    ' if ok else 'FAIL  ') + f'{model} at dp {dp}: tip {1e3 * tip:.4f} mm, Timoshenko '
          f'{1e3 * ti:.4f} mm (Euler-Bernoulli {1e3 * eb:.4f}): ratio {tip / ti:.4f} in [{lo}, {hi}]'
          f'; settled {r["settled"]} after {r["time"]:.3f} s')
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
