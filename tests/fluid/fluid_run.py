"""How far a fluid run got and what its probes say, for the check scripts:
a fluid_solver run (summary.json) or a coupled one (the coupler's
summary.json, with the fluid's own counts in fluid_summary.json)."""
import csv
import json
import os


def load(run):
    """(info, rows): info has status, message, simulated_time, end_time (the
    run's own), steps (fluid steps); rows are probes.csv's rows as floats."""
    with open(os.path.join(run, 'summary.json')) as f:
        s = json.load(f)
    fluid = s
    if s.get('program') == 'coupler':
        try:
            with open(os.path.join(run, 'fluid_summary.json')) as f:
                fluid = json.load(f)
        except OSError:
            fluid = {}
    info = {k: s.get(k) for k in ('status', 'message', 'simulated_time', 'end_time')}
    info['steps'] = fluid.get('steps')
    with open(os.path.join(run, 'probes.csv')) as f:  # '#' lines: the run's provenance
        rows = [{k: float(v) for k, v in r.items()}
                for r in csv.DictReader(l for l in f if not l.startswith('#'))]
    return info, rows


def unfinished(info, t_end=None):
    """Why the run does not cover [0, t_end] (t_end None: its own end_time), or None."""
    t, end = info.get('simulated_time') or 0.0, info.get('end_time')
    if info.get('status') != 'ok':
        return (f"run stopped at t = {t:g} s: status {info.get('status')}: "
                f"{info.get('message')}")
    if t_end is not None and t < t_end - 1e-9:
        return f"the run covers {t:g} s (its end_time), --t-end asks for {t_end:g} s"
    if end is not None and t < end - 1e-9:
        return f"run stopped at t = {t:g} s before its end_time {end:g} s"
    return None
