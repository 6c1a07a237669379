#!/usr/bin/python3
"""The solid's body-load probes against the coupler's own columns.

usage: body_load_check.py RUN [--fx plate_force_x] [--fy plate_force_y]
In a coupled run's probes.csv, the solid's force_x and force_y probes
(solid.probes, kind force_x / force_y without a body or summed over all
bodies; here the one body) and the coupler's solid_fx, solid_fy are both
means of the same fluid loads over each probe interval, each step weighted
by its dt (docs/sensors.md): they must agree row by row. Exit 0 if they do."""
import argparse, csv, os, sys


def rows(run):
    with open(os.path.join(run, 'probes.csv')) as f:  # '#': provenance
        return [{k: float(v) for k, v in r.items()}
                for r in csv.DictReader(l for l in f if not l.startswith('#'))]


def agree(run, fx='plate_force_x', fy='plate_force_y'):
    """(ok, message): the largest difference, relative to the largest force."""
    rs = rows(run)
    if not rs:
        return False, f'{run}: no probe rows'
    scale = max(max(abs(r['solid_fx']), abs(r['solid_fy'])) for r in rs)
    worst = max(max(abs(r[fx] - r['solid_fx']), abs(r[fy] - r['solid_fy'])) for r in rs)
    # the same sums (the solid's over its sub-steps, dt/n_sub each, the
    # coupler's over the steps) in another order, written with 9 significant
    # digits: 1e-7 of the largest force is rounding; a sampled instead of an
    # averaged load, or one body missed, is off by percents
    ok = scale > 0.0 and worst <= 1e-7 * scale
    return ok, (f'{len(rs)} rows: {fx}, {fy} vs the coupler\'s solid_fx, solid_fy: largest '
                f'difference {worst:.3g} N/m ({worst / scale if scale else 0:.1e} of the largest '
                f'force, {scale:.1f} N/m)')


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--fx', default='plate_force_x')
    ap.add_argument('--fy', default='plate_force_y')
    a = ap.parse_args()
    ok, msg = agree(a.run, a.fx, a.fy)
    print(('ok    ' if ok else 'FAIL  ') + msg)
    sys.exit(0 if ok else 1)


if __name__ == '__main__':
    main()
