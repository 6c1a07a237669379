#!/usr/bin/python3
"""Checks a solid_solver run of tests/solid/cases/block.yml (end 0.01 s,
snapshots every 0.005 s, probes every 0.001 s): every output exists, the
probe rows land exactly on their times, the clamp holds and the summary is
complete. usage: check_outputs.py OUTDIR"""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from host_expect import expected_host  # noqa: E402


def main():
    out = sys.argv[1]
    fails = []
    want = ["solid_000000.h5", "solid_000001.h5", "solid_000002.h5", "solid.xmf",
            "probes.csv", "summary.json"]
    for f in want:
        if not os.path.isfile(os.path.join(out, f)):
            fails.append(f"missing {f} (have {sorted(os.listdir(out))})")
    with open(os.path.join(out, "probes.csv")) as f:  # '#' lines: the run's provenance
        d = np.genfromtxt((l for l in f if not l.startswith("#")), delimiter=",", names=True)
    if list(d.dtype.names) != ["time", "tip_dy", "tip_x"]:
        fails.append(f"probes.csv columns {d.dtype.names}")
    if len(d) != 11 or np.max(np.abs(d["time"] - 0.001 * np.arange(11))) > 1e-12:
        fails.append(f"probe times {d['time']}")
    if not (d["tip_dy"][0] == 0.0 and d["tip_dy"][-1] < 0.0):
        fails.append(f"tip_dy {d['tip_dy']}: should start at 0 and sag")
    if abs(d["tip_x"][0] - 0.195) > 1e-12:
        fails.append(f"tip_x(0) = {d['tip_x'][0]}, expected 0.195")
    s = json.load(open(os.path.join(out, "summary.json")))
    for k in ("particles", "steps", "wall_seconds", "ns_per_particle_step", "solid"):
        if k not in s:
            fails.append(f"summary.json lacks {k}")
    if s.get("particles") != 115 or abs(s.get("time", 0) - 0.01) > 1e-15:
        fails.append(f"summary particles {s.get('particles')} time {s.get('time')}")
    if s.get("host") != expected_host():
        fails.append(f"summary host {s.get('host')!r}, expected {expected_host()!r}")
    phases = s.get("solid", {}).get("phase_seconds", {})
    if set(phases) != {"strain", "force", "update"}:
        fails.append(f"phase_seconds {phases}")
    xmf = open(os.path.join(out, "solid.xmf")).read()
    if xmf.count("<Time ") != 3:
        fails.append("solid.xmf does not list the 3 snapshots")
    for f in fails:
        print("FAIL: " + f)
    if not fails:
        print(f"ok: {s['steps']} steps, {s['ns_per_particle_step']:.0f} ns per particle-step")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
