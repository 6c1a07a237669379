#!/usr/bin/python3
"""The rolling tank with an elastic plate (cases/sloshing_low, sloshing_high):
runs, the paper's metric, stability counters, cost, and the plots of
docs/sloshing.md.

Each run is the coupler on a case with --set overrides; a run whose
summary.json says status ok is not run again (--force reruns). Then, per run,
from probes.csv and the summaries:
  - the paper's metric: the mean peak-to-peak amplitude of tip_dx over the
    paper's window (1.72-6.76 s low, 2.44-9.08 s high; a run shorter than the
    window uses what it has, said in the table), cycle by cycle between
    up-crossings of the window's mean, against the experiment's 1.44 / 14.65 cm;
    the error |A - A_exp| / A_exp as the paper's Tables 4 and 6;
  - the plate's period (mean spacing of those up-crossings), its mean crest
    and valley (high: experiment +7.38 / -7.52 cm);
  - stability: finished or not, fluid particles lost / escaped / put back by
    the tank guard, the solid's largest energy and whether its last cycles
    exceed its first ones;
  - cost: wall time, particles, coupling steps, solid sub-steps, the load
    average of the machine when the run started (os.getloadavg, written to
    RUN/bench.json).

usage: bench/sloshing_runs.py [--runs NAME...] [--out runs/sloshing] [--force]
                              [--table docs/sloshing_table.md] [--plots docs/img]
       bench/sloshing_runs.py --list
"""
import argparse
import json
import math
import os
import subprocess
import sys
import time

import numpy as np

from probes_csv import probes_table

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COUPLER = os.path.join(ROOT, 'build', 'bin', 'coupler')

EXP = {  # the experiment (Idelsohn et al. 2008, the paper's 5.4): window, p2p, period
    'low': dict(window=(1.72, 6.76), p2p=0.0144, period=1.70, paper={1.0: 27.08, 0.8: 27.78,
                                                                      0.5: 18.75}),
    'high': dict(window=(2.44, 9.08), p2p=0.1465, period=1.20, crest=0.0738, valley=-0.0752,
                 paper={1.0: 17.68, 0.8: 17.54, 0.5: 15.08}),
}

# At 2 mm the tank is 0.610 m wide (305 spacings): with 0.609 the floor's
# lattice stops 1.5 spacings short of the right wall and a particle creeps
# through that corner (one tank guard use in 2 s, docs/sloshing.md); the roll
# axis stays at the floor's middle. The coupling holds at the CFL step there.
COARSE = ['fluid.tank.width=0.610', 'fluid.blocks.1.x1=0.610', 'motion.pivot.x=0.305',
          'fluid.dt_max=1e-3', 'coupling.scheme=explicit']
# The runs of the paper's explicit coupling at 1 and 0.8 mm, at the step its
# added mass allows (the cases' setting until they became implicit, 2026-12-03)
EXPLICIT = ['coupling.scheme=explicit', 'fluid.dt_max=5e-5']
TLSPH = 'solid_solver --model tlsph'


def probes(path):
    """probes.csv as a structured array, one row or many (a 1-row file is 1-D too)."""
    return probes_table(path)


def run_list():
    """name -> (case, sets, solid command or None)."""
    r = {}
    for case in ('low', 'high'):
        for model in ('mps', 'tlsph'):
            solid = TLSPH if model == 'tlsph' else None
            # the MPS runs keep a snapshot every 0.01 s: the paper's picture instants
            pics = ['output.interval=0.01'] if model == 'mps' else []
            # The cases' quadratic TLSPH needs 3 particles through the plate
            # (solid_tlsph.c refuses 2): at 2 mm the linear correction
            lin = ['solid.tlsph.correction=linear'] if model == 'tlsph' else []
            r[f'{case}_2_{model}'] = (case, ['dp=0.002'] + pics + COARSE + lin, solid)
            # plane strain as it is, without the cases' 3D factor on plane stress
            r[f'{case}_2_{model}_strain'] = (case, ['dp=0.002', 'solid.plane=strain',
                                                    'solid.plane_factor=1',
                                                    'solid.courant=0.75'] + COARSE + lin, solid)
            r[f'{case}_1_{model}'] = (case, pics + EXPLICIT, solid)
            r[f'{case}_0.8_{model}'] = (case, ['dp=0.0008'] + EXPLICIT, solid)
    r['high_2_mps_table'] = ('high', ['dp=0.002', 'motion.kind=table', 'end_time=4.98'] + COARSE,
                             None)
    r['high_1_mps_table'] = ('high', ['motion.kind=table', 'end_time=4.98'] + EXPLICIT, None)
    # The implicit coupling lifts the explicit one's added-mass limit on the
    # step (docs/sloshing.md, "The implicit coupling lifts the limit"): the
    # fluid's CFL step, capped at 5e-4 s (the cases' setting since 2026-12-03)
    for case in ('low', 'high'):
        r[f'{case}_1_mps_implicit'] = (case, ['fluid.dt_max=5e-4', 'coupling.scheme=implicit',
                                              'output.interval=0.1'], None)
        r[f'{case}_0.8_mps_implicit'] = (case, ['dp=0.0008', 'fluid.dt_max=5e-4',
                                                'coupling.scheme=implicit', 'output.interval=0.1'],
                                         None)
        r[f'{case}_1_tlsph_implicit'] = (case, ['fluid.dt_max=5e-4', 'coupling.scheme=implicit',
                                                'output.interval=0.1'], TLSPH)
    # The low filling at 0.5 mm (thirty-first session): the plate's lattice
    # at 0.5 mm (solid.refine=1), the 1 mm case's, since the case's refine=2
    # would be 0.25 mm there, four times the solid's particles at half its step
    r['low_0.5_mps_implicit'] = ('low', ['dp=0.0005', 'solid.refine=1', 'fluid.dt_max=5e-4',
                                         'coupling.scheme=implicit', 'output.interval=0.1'], None)
    # The high filling at 0.5 mm (thirty-third session): the case as it is
    # (its plate unrefined, 8 particles across at 0.5 mm); started, not finished
    # (with the iteration log that bench/coupling_iterations.py reads)
    r['high_0.5_mps_implicit'] = ('high', ['dp=0.0005', 'fluid.dt_max=5e-4',
                                           'coupling.scheme=implicit', 'output.interval=0.1',
                                           'coupling.implicit.log=true'], None)
    # the measured roll at 1 mm with the case's setting (twenty-ninth session),
    # against high_1_mps_implicit over the cycles both hold
    r['high_1_mps_implicit_table'] = ('high', ['fluid.dt_max=5e-4', 'coupling.scheme=implicit',
                                               'output.interval=0.1', 'motion.kind=table',
                                               'end_time=4.98'], None)
    return r


def do_run(name, spec, out, force, extra, coupler=COUPLER):
    case, sets, solid = spec
    d = os.path.join(out, name)
    sp = os.path.join(d, 'summary.json')
    if not force and os.path.exists(sp) and json.load(open(sp)).get('status') == 'ok':
        return
    os.makedirs(d, exist_ok=True)
    cmd = [coupler, os.path.join(ROOT, 'cases', f'sloshing_{case}', 'case.yml'), '--out', d,
           '--quiet']
    for s in sets + extra:
        cmd += ['--set', s]
    if solid:
        cmd += ['--solid', solid]
    load = os.getloadavg()
    with open(os.path.join(d, 'bench.json'), 'w') as f:
        json.dump({'command': ' '.join(cmd), 'loadavg_start': load,
                   'started': time.strftime('%Y-%m-%d %H:%M:%S')}, f)
    print(f'{name}: {" ".join(cmd)} (load {load[0]:.1f})', file=sys.stderr, flush=True)
    subprocess.run(cmd)


def cycles(t, x, lo, hi, band=1.0, smooth=0.0):
    """Cycles of x between up-crossings of its mean over [lo, hi]: list of
    (t_start, t_end, max, min). An up-crossing counts only after x has been
    below the mean by band x its standard deviation since the last one: a
    refined plate (solid.refine) rings at its own ~10 Hz on top of the roll's
    period, and each ripple through the mean would otherwise start a cycle
    (a sinusoid's crossings are untouched: it dips to -1.4 std). Half a
    standard deviation, the first choice, let a ripple of the low filling's
    2 mm refined plate through (2026-12-03: three "cycles" of 1.11 s where
    there are two of 1.67); one is still clear of the sinusoid's trough, and
    reads every other run of this page as before.
    smooth (s, 0 = off): the crossings are found on x's running mean over
    that time, the crests and troughs still read from x itself. The low
    filling's 2 mm plate with the side walls' inertia (2026-12-03) jitters by
    0.2-0.4 cm in spikes of about 0.1 s on a 1.3 cm swing, deep enough to
    arm and cross the mean inside a half cycle: four "cycles" of 0.83 s.
    analyse() passes a quarter of the experiment's period, which a ripple of
    0.1 s does not survive and a swing of 1.2-1.7 s does (its crossings move
    by nothing: a centred mean of a sinusoid crosses where it does)."""
    m = (t >= lo) & (t <= hi)
    tt, xx = t[m], x[m]
    if len(tt) < 3:
        return []
    if smooth > 0.0:
        w = max(1, int(round(smooth / float(np.median(np.diff(t))))))
        xs = np.convolve(x, np.ones(w) / w, mode='same')[m]
    else:
        xs = xx
    s = xs - xs.mean()
    h = band * float(s.std())
    up, armed = [], False
    for k in range(len(s) - 1):
        armed = armed or s[k] < -h
        if armed and s[k] < 0 <= s[k + 1]:
            up.append(tt[k] - s[k] * (tt[k + 1] - tt[k]) / (s[k + 1] - s[k]))
            armed = False
    out = []
    for a, b in zip(up[:-1], up[1:]):
        k = (tt >= a) & (tt <= b)
        out.append((a, b, float(xx[k].max()), float(xx[k].min())))
    return out


def analyse(name, spec, out):
    case, sets, solid = spec
    d = os.path.join(out, name)
    res = {'name': name, 'case': case,
           'model': ('tlsph' + (' linear' if 'solid.tlsph.correction=linear' in sets else
                                ' quadratic')) if solid else 'mps',
           'plane': 'strain' if 'solid.plane=strain' in sets else 'stress',
           'motion': 'table' if 'motion.kind=table' in sets else 'sinusoid'}
    dp = next((float(s.split('=')[1]) for s in sets if s.startswith('dp=')), 0.001)
    res['dp'] = dp
    try:
        summ = json.load(open(os.path.join(d, 'summary.json')))
        fl = json.load(open(os.path.join(d, 'fluid_summary.json')))
        so = json.load(open(os.path.join(d, 'solid_summary.json')))
        p = probes(os.path.join(d, 'probes.csv'))
    except (OSError, ValueError) as e:
        res['missing'] = str(e)
        return res
    bj = os.path.join(d, 'bench.json')
    res['load'] = json.load(open(bj))['loadavg_start'][0] if os.path.exists(bj) else float('nan')
    res['status'] = summ['status']
    res['message'] = summ.get('message', '')
    res['t_reached'] = summ['simulated_time']
    res['wall'] = summ['wall_seconds']
    # a resumed run's wall time is its last segment's, from this time on
    res['resumed_at'] = (summ.get('restart') or {}).get('time')
    res['git_rev'] = summ.get('git_rev', '')
    res['steps'] = summ['coupling_steps']
    res['messaging'] = summ.get('messaging_fraction', float('nan'))
    res['host'] = summ.get('host', '')
    res['n_fluid'] = fl['particles']['fluid']
    res['n_solid_iface'] = fl['particles']['solid']
    res['substeps'] = so.get('substeps', 0)
    ms = so.get('model_summary', {})
    if ms.get('refine', 1) > 1:  # solid.refine: the solid k times finer than the fluid
        res['model'] += f", refine {ms['refine']}"
    res['lost'] = fl.get('lost_particles', 0)
    res['guard'] = fl.get('wall_guard_uses', 0)
    res['escaped'] = float(p['escaped'].max())
    t, x = p['time'], p['tip_dx']
    e = p['solid_energy']
    res['energy_max'] = float(e.max())
    res['energy_t'] = float(t[np.argmax(e)])
    # bounded: the last 2 s hold no more than 3x the largest energy of 2-4 s
    late, mid = e[t >= t[-1] - 2.0], e[(t >= 2.0) & (t <= 4.0)]
    res['energy_ratio'] = float(late.max() / mid.max()) if len(mid) and len(late) and \
        t[-1] > 6.0 else float('nan')
    ex = EXP[case]
    lo, hi = ex['window']
    cyc = cycles(t, x, lo, min(hi, t[-1]), smooth=ex['period'] / 4)
    res['window'] = (lo, min(hi, float(t[-1])))
    res['ncycles'] = len(cyc)
    if cyc:
        p2p = [c[2] - c[3] for c in cyc]
        res['p2p'] = float(np.mean(p2p))
        res['crest'] = float(np.mean([c[2] for c in cyc]))
        res['valley'] = float(np.mean([c[3] for c in cyc]))
        res['period'] = float(np.mean([c[1] - c[0] for c in cyc]))
        res['error'] = abs(res['p2p'] - ex['p2p']) / ex['p2p']
    res['tip_max'] = float(np.abs(x).max())
    return res


def fmt_time(s):
    return f'{s / 60:.1f} min' if s >= 60 else f'{s:.0f} s'


def table(rows):
    out = ['| run | solid | dp | reached | paper metric: mean p2p (exp.) | error (paper) | '
           'period (exp.) | crest / valley (exp.) | stability: lost / escaped / guard; '
           'energy max (late / mid) | wall time (load) | fluid / solid iface particles | '
           'coupling steps | solid sub-steps |',
           '|---|---|---|---|---|---|---|---|---|---|---|---|---|']
    for r in rows:
        if 'missing' in r:
            out.append(f"| {r['name']} | | | not run | | | | | | | | | |")
            continue
        ex = EXP[r['case']]
        paper = ex['paper'].get(round(r['dp'] * 1e3, 1))
        ok = r['status'] == 'ok'
        reached = f"{r['t_reached']:.2f} s" + ('' if ok else f" ({r['status']})")
        if r.get('ncycles'):
            win = f"{r['window'][0]:g}-{r['window'][1]:.2f} s, {r['ncycles']} cycles"
            metric = f"{r['p2p'] * 100:.2f} cm ({ex['p2p'] * 100:.2f}; {win})"
            err = f"{r['error'] * 100:.1f}%" + (f' ({paper:.2f}%)' if paper else '')
            per = f"{r['period']:.3f} s ({ex['period']:.2f})"
            cv = f"{r['crest'] * 100:+.2f} / {r['valley'] * 100:+.2f} cm" + (
                f" ({ex['crest'] * 100:+.2f} / {ex['valley'] * 100:+.2f})" if 'crest' in ex else '')
        else:
            metric, err, per, cv = 'no cycle in the window', '', '', ''
        stab = (f"{r['lost']} / {r['escaped']:.0f} / {r['guard']}; {r['energy_max']:.3g} J/m at "
                f"{r['energy_t']:.2f} s" + ('' if math.isnan(r['energy_ratio']) else
                                            f" ({r['energy_ratio']:.2f})"))
        plane = '' if r['plane'] == 'stress' else ', plane strain'
        motion = '' if r['motion'] == 'sinusoid' else ', measured roll'
        resumed = '' if r.get('resumed_at') is None else f" from {r['resumed_at']:.2f} s"
        out.append(f"| {r['name']} | {r['model']}{plane}{motion} | {r['dp'] * 1e3:g} mm | {reached} | "
                   f"{metric} | {err} | {per} | {cv} | {stab} | {fmt_time(r['wall'])}{resumed} "
                   f"({r['load']:.1f}) | {r['n_fluid']:,} / {r['n_solid_iface']} | {r['steps']:,} | "
                   f"{r['substeps']:,} |")
    return '\n'.join(out)


def phases(rows, out):
    """Where the wall time goes, per run: the coupler's split (fluid, solid,
    messaging), the time per coupling step and per fluid particle-step, and the
    fluid's phases (fluid_summary.json). A markdown table."""
    names = ('neighbours', 'predict', 'density', 'ppe_assemble', 'ppe_solve', 'correct')
    out_rows = ['| run | steps | wall per step | fluid / solid / messaging | ns per fluid '
                'particle-step | fluid: ' + ' / '.join(names) + ' | PPE iterations per step |',
                '|---|---|---|---|---|---|---|']
    for r in rows:
        if 'missing' in r:
            continue
        d = os.path.join(out, r['name'])
        summ = json.load(open(os.path.join(d, 'summary.json')))
        fl = json.load(open(os.path.join(d, 'fluid_summary.json')))
        sp = dict(summ['time_split_seconds'])
        w = summ['wall_seconds']
        if not sp['fluid']:  # an interrupted run: the coupler has no split, the solvers do
            so = json.load(open(os.path.join(d, 'solid_summary.json')))
            sp['fluid'], sp['solid'] = fl['compute_seconds'], so['compute_seconds']
            sp['messaging'] = w - sp['fluid'] - sp['solid']
        ph = fl['phase_seconds']
        tot = sum(ph.values())
        # resumed: the wall time covers the last segment, the steps the whole run
        per_step = ('- (resumed)' if r.get('resumed_at') is not None
                    else f"{1e3 * w / max(r['steps'], 1):.1f} ms")
        out_rows.append(
            f"| {r['name']} | {r['steps']:,} | {per_step} | "
            f"{100 * sp['fluid'] / w:.0f}% / {100 * sp['solid'] / w:.0f}% / "
            f"{100 * sp['messaging'] / w:.0f}% | {fl['ns_per_particle_step']:.0f} | "
            + ' / '.join(f"{100 * ph[k] / tot:.0f}%" for k in names)
            + f" | {fl['ppe_iterations_per_step']:.1f} |")
    return '\n'.join(out_rows)


def table_vs_sinusoid(rows, out, window=None):
    """The measured roll against the sinusoid, over the window both runs hold
    (the table ends at 4.98 s; window=(lo, hi) narrows it, e.g. to before a
    divergence): mean peak-to-peak, crest, valley, period of each, and their
    relative difference. Lines of markdown."""
    lines = []
    by = {r['name']: r for r in rows}
    for r in rows:
        if r['motion'] != 'table' or 'missing' in r or (r.get('t_reached', 0) < 3.5 and
                                                          not window):
            continue
        s = by.get(r['name'].replace('_table', ''))
        if not s or 'missing' in s:
            continue
        lo, hi = EXP[r['case']]['window'][0], min(r['t_reached'], s['t_reached'])
        if window:
            lo, hi = window[0], min(hi, window[1])
        got = {}
        for q in (r, s):
            p = probes(os.path.join(out, q['name'], 'probes.csv'))
            cyc = cycles(p['time'], p['tip_dx'], lo, hi, smooth=EXP[r['case']]['period'] / 4)
            if not cyc:
                break
            got[q['motion']] = (float(np.mean([c[2] - c[3] for c in cyc])),
                                float(np.mean([c[2] for c in cyc])),
                                float(np.mean([c[3] for c in cyc])),
                                float(np.mean([c[1] - c[0] for c in cyc])), len(cyc))
        if len(got) < 2:
            continue
        a, b = got['table'], got['sinusoid']
        lines.append(f"{r['name']} against {s['name']} over {lo:g}-{hi:.2f} s: mean p2p "
                     f"{a[0] * 100:.2f} / {b[0] * 100:.2f} cm ({100 * (a[0] / b[0] - 1):+.1f}%), "
                     f"crest {a[1] * 100:+.2f} / {b[1] * 100:+.2f} cm, valley {a[2] * 100:+.2f} / "
                     f"{b[2] * 100:+.2f} cm, period {a[3]:.3f} / {b[3]:.3f} s "
                     f"({a[4]} / {b[4]} cycles)")
    return lines


def plot_tip(rows, out, case, path, names=None):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    ex = EXP[case]
    fig, ax = plt.subplots(figsize=(10, 3.8))
    for r in rows:
        if r['case'] != case or 'missing' in r or (names and r['name'] not in names):
            continue
        if r['t_reached'] < 1.0:  # a timing run (1 mm): nothing to see at this scale
            continue
        p = probes(os.path.join(out, r['name'], 'probes.csv'))
        ax.plot(p['time'], p['tip_dx'] * 100, lw=0.9, label=r['name'])
    lo, hi = ex['window']
    if 'crest' in ex:
        ax.axhspan(ex['valley'] * 100, ex['crest'] * 100, color='0.85', zorder=0,
                   label='experiment: valley to crest')
    else:
        ax.axhspan(-ex['p2p'] * 50, ex['p2p'] * 50, color='0.85', zorder=0,
                   label='experiment: mean peak-to-peak, centred')
    ax.axvline(lo, color='k', lw=0.6, ls=':')
    ax.axvline(hi, color='k', lw=0.6, ls=':', label='the paper\'s window')
    ax.set_xlabel('t (s)')
    ax.set_ylabel('tip_dx, tank frame (cm)')
    ax.set_title(f'sloshing {case} filling: plate tip')
    ax.legend(fontsize=7, ncol=3, loc='upper right')
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--runs', nargs='+', default=None)
    ap.add_argument('--out', default=os.path.join(ROOT, 'runs', 'sloshing'))
    ap.add_argument('--coupler', default=COUPLER, help='the coupler to run (default: %(default)s)')
    ap.add_argument('--force', action='store_true')
    ap.add_argument('--no-run', action='store_true', help='analyse what is there')
    ap.add_argument('--set', action='append', default=[], help='extra --set for every run')
    ap.add_argument('--table', default=None)
    ap.add_argument('--json', default=None)
    ap.add_argument('--plots', default=None, help='directory for the tip plots')
    ap.add_argument('--list', action='store_true')
    ap.add_argument('--compare-window', type=float, nargs=2, default=None, metavar=('LO', 'HI'),
                    help='the measured roll against the sinusoid over LO-HI s')
    a = ap.parse_args()
    runs = run_list()
    if a.list:
        for k, v in runs.items():
            print(k, v)
        return
    names = a.runs or list(runs)
    for n in names:
        if n not in runs:
            sys.exit(f'unknown run {n} (--list)')
    if not a.no_run:
        for n in names:
            do_run(n, runs[n], a.out, a.force, a.set, a.coupler)
    rows = [analyse(n, runs[n], a.out) for n in names]
    revs = sorted({r.get('git_rev', '') for r in rows if 'missing' not in r} - {''})
    text = (f"Written by bench/sloshing_runs.py on {time.strftime('%Y-%m-%d')} from the runs in "
            f"{a.out} (builds {', '.join(revs) or 'unknown'}).\n\n" + table(rows))
    extra = table_vs_sinusoid(rows, a.out, a.compare_window) + [phases(rows, a.out)]
    if extra:
        text += '\n\n' + '\n\n'.join(extra)
    print(text)
    if a.table:
        with open(a.table, 'w') as f:
            f.write(text + '\n')
    if a.json:
        with open(a.json, 'w') as f:
            json.dump(rows, f, indent=1, default=str)
    if a.plots:
        for case in ('low', 'high'):
            plot_tip(rows, a.out, case, os.path.join(a.plots, f'sloshing_{case}_tip.png'))


if __name__ == '__main__':
    main()
