#!/usr/bin/python3
"""Checks an elastic-gate run: the water pushes the gate's free end
downstream and up. At 0.12 s the experiment (Antoci et al. 2007) has the end
about 3 cm downstream; coarse runs (the gate 2 particles thick) must show it
moving the right way by at least 1 cm, stay below the gate's length, and keep
tip_dy >= -2 mm (the end cannot go down into the floor)."""
import csv, os, sys

rows = list(csv.DictReader(open(os.path.join(sys.argv[1], 'probes.csv'))))
dx = [float(r['tip_dx']) for r in rows]
dy = [float(r['tip_dy']) for r in rows]
ok = max(dx) >= 0.01 and max(dx) <= 0.079 and min(dy) >= -0.002 and dx[-1] > 0
print(f"tip dx max {100 * max(dx):.2f} cm, final {100 * dx[-1]:.2f} cm, dy min {1000 * min(dy):.2f} mm:",
      'ok' if ok else 'FAIL')
sys.exit(0 if ok else 1)
