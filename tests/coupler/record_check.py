#!/usr/bin/python3
"""The files of a run say what ran (issue 23, docs/output.md).

usage: record_check.py BUILD_DIR OUT_DIR CHECK   (from the repository root)
CHECK:
  tlsph   coupler + `--solid "solid_solver --model tlsph"`: case_resolved.yml
          and every snapshot's /config name the command and solid.model tlsph,
          and the run.* record (command line, host name, start time) the
          summary and probes.csv's '#' lines also carry; fluid snapshots hold
          only fluid, wall and dummy particles (types 0-2, legend attribute),
          ids unique, so scene.xmf draws every particle once.
  python  coupler + the Python solid: its snapshots are HDF5, numbered
          0, 1, 2, ... like the C solvers', and scene.xmf shows them; the
          resolved case names the program and its HELLO model.
  lost    a dam break in a low open tank, through the coupler and alone: the
          particles that leave over a wall are said on the terminal and are in
          the summaries.
Exit 0 if every check holds; one line per failure otherwise."""
import csv
import glob
import json
import os
import re
import subprocess
import sys

import h5py
import yaml

fails = []


def check(ok, what):
    print(('ok   ' if ok else 'FAIL ') + what)
    if not ok:
        fails.append(what)


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=300)
    if r.returncode != 0:
        sys.exit(f'record_check: {" ".join(cmd)} exited with {r.returncode}:\n{r.stderr}')
    return r.stderr


def load_yaml(text):
    """Every scalar a string, as the C loader reads them (PyYAML's own loader
    would turn run.started into a datetime)."""
    return yaml.load(text, Loader=yaml.BaseLoader)


def config(h5path):
    with h5py.File(h5path, 'r') as h:
        return load_yaml(h['config'][()].decode())


def comments(path):
    """The leading '# key: value' lines of a text file, as a dict."""
    out = {}
    with open(path) as f:
        for line in f:
            if not line.startswith('#'):
                break
            k, _, v = line[1:].strip().partition(': ')
            out[k] = v
    return out


def scene_grids(out):
    """Per scene time, the (file, NumberOfElements) of each member grid."""
    text = open(os.path.join(out, 'scene.xmf')).read()
    frames = text.split('CollectionType="Spatial"')[1:]
    return [re.findall(r'NumberOfElements="(\d+)"[^<]*>\s*<DataItem[^>]*>([^:<]+):/topology', f)
            for f in frames]


def check_tlsph(build, out):
    run([f'{build}/bin/coupler', 'cases/dambreak_elastic_plate/case.yml', '--out', out, '--quiet',
         '--set', 'dp=0.006', '--set', 'end_time=0.06', '--set', 'output.interval=0.02',
         '--solid', 'solid_solver --model tlsph'])
    resolved = os.path.join(out, 'case_resolved.yml')
    case = load_yaml(open(resolved).read())
    check(case['solid']['model'] == 'tlsph', f"case_resolved.yml solid.model = {case['solid']['model']}")
    check(case['solid_solver'] == 'solid_solver --model tlsph',
          f"case_resolved.yml solid_solver = {case['solid_solver']!r}")
    rec = case['run']
    check('--solid' in rec['command'] and 'coupler' in rec['command'],
          f"run.command = {rec['command']!r}")
    check(bool(rec['hostname']) and bool(rec['host']), f"run.hostname, run.host = {rec['hostname']!r}, "
          f"{rec['host']!r}")
    check(re.fullmatch(r'\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ', rec['started']) is not None,
          f"run.started = {rec['started']!r}")
    head = comments(resolved)
    check(head.get('solid program') == 'solid_solver --model tlsph (HELLO model=tlsph)',
          f"case_resolved.yml names the solid program: {head.get('solid program')!r}")
    snaps = sorted(glob.glob(os.path.join(out, '*_0*.h5')))
    check(len(snaps) == 8, f'{len(snaps)} snapshots (4 fluid, 4 solid)')
    bad = [os.path.basename(p) for p in snaps
           if (lambda c: c['solid']['model'] != 'tlsph' or c['solid_solver'] != case['solid_solver']
               or c['run'] != rec)(config(p))]
    check(not bad, f'every /config says solid.model tlsph, the command and the run record '
          f'{"(not: " + ", ".join(bad) + ")" if bad else ""}')
    fluid = sorted(glob.glob(os.path.join(out, 'fluid_0*.h5')))
    counts, types, dup = set(), set(), []
    for p in fluid:
        with h5py.File(p, 'r') as h:
            t, ids = h['particles/type'][:], h['particles/id'][:]
            legend = h['particles/type'].attrs.get('legend', b'')
            counts.add(len(t))
            types |= set(t.tolist())
            if len(set(ids.tolist())) != len(ids):
                dup.append(os.path.basename(p))
            check(h['particles/velocity'].shape == (len(t), 3) and
                  h['particles/position'].shape == (len(t), 3),
                  f'{os.path.basename(p)}: position and velocity n x 3')
    legend = legend.decode() if isinstance(legend, bytes) else legend
    check(types <= {0, 1, 2} and legend.startswith('0 fluid, 1 wall'),
          f'fluid snapshots hold types {sorted(types)}, legend {legend!r}')
    check(len(counts) == 1, f'fluid particle count the same in every snapshot: {sorted(counts)}')
    check(not dup, f'fluid ids unique in every file {dup if dup else ""}')
    with h5py.File(os.path.join(out, 'solid_000000.h5'), 'r') as h:
        nsolid = len(h['particles/id'])
        sid = h['particles/id'][:]
    check(len(set(sid.tolist())) == nsolid, f'solid ids unique ({nsolid} particles)')
    frames = scene_grids(out)
    want = [[(str(list(counts)[0]), f'fluid_{k:06d}.h5'), (str(nsolid), f'solid_{k:06d}.h5')]
            for k in range(4)]
    check(frames == want, f'scene.xmf: each time one fluid grid and one solid grid, every '
          f'particle once ({frames[:1]}...)')
    head = comments(os.path.join(out, 'probes.csv'))
    check(head.get('program', '').startswith('coupler ') and head.get('command') == rec['command']
          and head.get('hostname') == rec['hostname'] and head.get('started') == rec['started']
          and head.get('case') == 'cases/dambreak_elastic_plate/case.yml',
          f'probes.csv # lines: {head}')
    with open(os.path.join(out, 'probes.csv')) as f:
        rows = list(csv.DictReader(l for l in f if not l.startswith('#')))
    check(rows and list(rows[0])[:1] == ['time'] and 'tip_dx' in rows[0], 'probes.csv columns '
          f'{list(rows[0]) if rows else None}')
    try:
        import pandas as pd
        d = pd.read_csv(os.path.join(out, 'probes.csv'), comment='#')
        check(list(d.columns) == list(rows[0]) and len(d) == len(rows),
              f"pandas read_csv(comment='#'): {len(d)} rows")
    except ImportError:
        print('INFO pandas not installed: its reading not checked')
    s = json.load(open(os.path.join(out, 'summary.json')))
    check(s['solvers']['solid']['model'] == 'tlsph' and s['command'] == rec['command'] and
          s['started'] == rec['started'] and s['solvers']['solid']['command'] == case['solid_solver'],
          f"summary.json: solid model {s['solvers']['solid']['model']}, command, started")


def check_python(build, out):
    run([f'{build}/bin/coupler', 'cases/dambreak_elastic_plate/case.yml', '--out', out, '--quiet',
         '--set', 'dp=0.006', '--set', 'end_time=0.06', '--set', 'output.interval=0.02',
         '--solid', '/usr/bin/python3 solid_solver/python/modal_beam_solid.py'])
    names = sorted(os.path.basename(p) for p in glob.glob(os.path.join(out, 'solid_*.h5')))
    check(names == [f'solid_{k:06d}.h5' for k in range(4)], f'Python solid snapshots {names}')
    check(not glob.glob(os.path.join(out, 'solid_*.csv')), 'no CSV snapshots')
    times = []
    for n in names:
        with h5py.File(os.path.join(out, n), 'r') as h:
            times.append(round(float(h.attrs['time']), 9))
            ok = h['particles/position'].shape[1] == 3 and len(h['topology']) == len(h['particles/id'])
    check(times == [0.0, 0.02, 0.04, 0.06] and ok, f'their times {times}, 3-component positions')
    frames = scene_grids(out)
    check(len(frames) == 4 and all(len(f) == 2 and f[1][1] == f'solid_{k:06d}.h5'
                                   for k, f in enumerate(frames)),
          f'scene.xmf shows the plate at every time ({[f[-1][1] for f in frames]})')
    head = comments(os.path.join(out, 'case_resolved.yml'))
    check(head.get('solid program') == '/usr/bin/python3 solid_solver/python/modal_beam_solid.py '
          '(HELLO model=modal_beam)', f"case_resolved.yml: {head.get('solid program')!r}")


def check_lost(build, out):
    # a 0.3 m square open tank: the run-up jet throws 8 particles over the
    # right wall by 1 s at dp 0.01 (the wall sensor moves with the wall)
    low = ['cases/dambreak/case.yml', '--set', 'dp=0.01', '--set', 'end_time=1.0', '--set',
           'fluid.tank.height=0.3', '--set', 'fluid.tank.width=0.3', '--set',
           'fluid.probes.4.x=0.3', '--set',
           'fluid.tank.lid=false', '--set', 'output.interval=0', '--quiet']
    for prog, sub, summary in (('coupler', 'coupled', 'fluid_summary.json'),
                               ('fluid_solver', 'alone', 'summary.json')):
        err = run([f'{build}/bin/{prog}', low[0], '--out', os.path.join(out, sub), *low[1:]])
        lost = json.load(open(os.path.join(out, sub, summary)))['lost_particles']
        said = re.search(r'^' + prog + r': (\d+) fluid particles? left over the open tank walls',
                         err, re.M)
        check(lost > 0 and said is not None and int(said.group(1)) == lost,
              f'{prog}: {lost} particles lost, the terminal says: {err.strip()!r}')
        if prog == 'coupler':
            top = json.load(open(os.path.join(out, sub, 'summary.json'))).get('lost_particles')
            check(top == lost, f"coupler summary.json lost_particles = {top}")


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    build, out, what = sys.argv[1:]
    {'tlsph': check_tlsph, 'python': check_python, 'lost': check_lost}[what](build, out)
    if fails:
        print(f'record_check {what}: {len(fails)} failed: ' + '; '.join(fails), file=sys.stderr)
    sys.exit(1 if fails else 0)


if __name__ == '__main__':
    main()
