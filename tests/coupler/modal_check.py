#!/usr/bin/python3
"""Checks the coupled run with the Python modal-beam solid: it answered every
step, reported its probe, and its plate bent downstream under the water
(the flexible test plate of plate_in_water.yml deflects several mm in 0.3 s)."""
import csv, json, os, sys

run = sys.argv[1]
with open(os.path.join(run, 'probes.csv')) as f:
    rows = list(csv.DictReader(l for l in f if not l.startswith('#')))  # '#': provenance
tip = [float(r['tip_dx']) for r in rows]
s = json.load(open(os.path.join(run, 'summary.json')))
ok = s['status'] == 'ok' and max(tip) > 0.005 and all(t > -1e-3 for t in tip)
print(f"status {s['status']}, tip max {1000 * max(tip):.1f} mm:", 'ok' if ok else 'FAIL')
sys.exit(0 if ok else 1)
