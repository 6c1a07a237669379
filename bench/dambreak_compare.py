#!/usr/bin/python3
"""Compare a dam-break run's probes.csv with Martin & Moyce (1952).

usage: dambreak_compare.py RUN_DIR [--a 0.146] [--tmax 3.0] [--json]
Prints the front Z(T) and height H(tau) errors at the table points up to
T = tmax (tau up to the run's end), the max relative front error and whether
it is within the issue's 10% target. Reference: cases/dambreak/martin_moyce.csv.
"""
import argparse, csv, json, math, os, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
REF = os.path.join(HERE, '..', 'cases', 'dambreak', 'martin_moyce.csv')


def run_dambreak(binary, threads, sets, prefix='db_', quiet_stderr=False):
    """Runs cases/dambreak without snapshots, with `--set` for each of sets
    ('key=value'), on `threads` OpenMP threads. Returns (output directory,
    summary.json as a dict, whether it exited 0, the command relative to the
    repository)."""
    out = tempfile.mkdtemp(prefix=prefix)
    cmd = [os.path.join(binary, 'fluid_solver'), os.path.join(ROOT, 'cases/dambreak/case.yml'),
           '--out', out, '--quiet', '--set', 'output.interval=0']
    for kv in sets:
        cmd += ['--set', kv]
    rc = subprocess.run(cmd, env=dict(os.environ, OMP_NUM_THREADS=str(threads)),
                        stderr=subprocess.PIPE if quiet_stderr else None).returncode
    with open(os.path.join(out, 'summary.json')) as f:
        summary = json.load(f)
    return out, summary, rc == 0, ' '.join(cmd).replace(ROOT + '/', '')


def load_ref(path=REF):
    series = {}
    with open(path) as f:
        rows = [l for l in f if not l.startswith('#')]
    for r in csv.DictReader(rows):
        series.setdefault(r['series'], []).append((float(r['x']), float(r['y'])))
    return series


def load_probes(run):
    with open(os.path.join(run, 'probes.csv')) as f:
        rd = csv.DictReader(l for l in f if not l.startswith('#'))  # '#': provenance
        cols = {k: [] for k in rd.fieldnames}
        for r in rd:
            for k in cols:
                cols[k].append(float(r[k]))
    return cols


def interp(xs, ys, x):
    if x < xs[0] or x > xs[-1]:
        return None
    for k in range(1, len(xs)):
        if xs[k] >= x:
            t = (x - xs[k - 1]) / (xs[k] - xs[k - 1]) if xs[k] > xs[k - 1] else 0.0
            return ys[k - 1] + t * (ys[k] - ys[k - 1])
    return ys[-1]


def compare(run, a=0.146, tmax=3.0, g=9.81):
    ref = load_ref()
    pr = load_probes(run)
    t = pr['time']
    out = {'front': [], 'height': []}
    for T, Z in ref['mm_table_T_Z']:
        if T > tmax:
            continue
        x = interp(t, pr['front'], T / math.sqrt(2 * g / a))
        if x is not None:
            out['front'].append((T, Z, x / a, (x / a - Z) / Z))
    for tau, H in ref['mm_table_tau_H']:
        h = interp(t, pr['height'], tau / math.sqrt(g / a))
        if h is not None:
            out['height'].append((tau, H, h / (2 * a), (h / (2 * a) - H) / H))
    fe = [abs(e[3]) for e in out['front']]
    he = [abs(e[3]) for e in out['height']]
    out['front_max_rel_err'] = max(fe) if fe else None
    out['front_mean_rel_err'] = sum(fe) / len(fe) if fe else None
    out['height_max_rel_err'] = max(he) if he else None
    out['height_mean_rel_err'] = sum(he) / len(he) if he else None
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('run')
    ap.add_argument('--a', type=float, default=0.146)
    ap.add_argument('--tmax', type=float, default=3.0)
    ap.add_argument('--json', action='store_true')
    ap.add_argument('--max-front-err', type=float, default=None,
                    help='exit 1 if the max relative front error exceeds this')
    args = ap.parse_args()
    r = compare(args.run, args.a, args.tmax)
    if args.json:
        print(json.dumps(r))
    else:
        print('   T     Z_mm   Z_sim   err')
        for T, Z, z, e in r['front']:
            print(f'{T:5.2f}  {Z:6.2f}  {z:6.2f}  {100*e:+6.1f}%')
        print('  tau    H_mm   H_sim   err')
        for T, H, h, e in r['height']:
            print(f'{T:5.2f}  {H:6.2f}  {h:6.2f}  {100*e:+6.1f}%')
        print(f"front: max |err| {100*r['front_max_rel_err']:.1f}%, mean {100*r['front_mean_rel_err']:.1f}%")
        if r['height_max_rel_err'] is not None:
            print(f"height: max |err| {100*r['height_max_rel_err']:.1f}%, mean {100*r['height_mean_rel_err']:.1f}%")
    if args.max_front_err is not None and not (r['front_max_rel_err'] <= args.max_front_err):
        sys.exit(1)


if __name__ == '__main__':
    main()
