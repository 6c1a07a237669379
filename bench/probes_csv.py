"""Reading the CSV files the solvers write (probes.csv, the step logs): the
'#' lines at the top are provenance (docs/output.md), the first other line
holds the column names. One reader for the bench scripts and the checkers
of tests/ (which put bench/ on their path)."""
import numpy as np


def csv_rows(path):
    """The lines of a CSV but its '#' provenance header."""
    with open(path) as f:
        return [line for line in f if not line.startswith('#')]


def probes_table(path):
    """A CSV as a structured array with named columns, one row or many (a
    one-row file reads as 1-D too)."""
    return np.atleast_1d(np.genfromtxt(csv_rows(path), delimiter=',', names=True))
