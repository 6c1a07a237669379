"""Reading what a run leaves (probes.csv and the step logs, whose '#' lines
at the top are provenance and whose first other line holds the column
names, docs/output.md; summary.json): one reader for the bench scripts and
the checkers of tests/ (which put bench/ on their path)."""
import json
import os

import numpy as np


def finished(run, t_end):
    """(summary.json of the run, None if it ran to t_end with status ok, else
    one line saying why not)."""
    with open(os.path.join(run, 'summary.json')) as f:
        summ = json.load(f)
    if summ.get('status') != 'ok' or summ.get('simulated_time', 0.0) < t_end - 1e-9:
        return summ, f"run did not finish: status {summ.get('status')}: {summ.get('message')}"
    return summ, None


def csv_rows(path):
    """The lines of a CSV but its '#' provenance header."""
    with open(path) as f:
        return [line for line in f if not line.startswith('#')]


def probes_table(path):
    """A CSV as a structured array with named columns, one row or many (a
    one-row file reads as 1-D too)."""
    return np.atleast_1d(np.genfromtxt(csv_rows(path), delimiter=',', names=True))
