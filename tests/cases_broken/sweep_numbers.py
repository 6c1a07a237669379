#!/usr/bin/env python3
"""Every number key of the cases at absurd values: 0, -1e300, 1e300, 1e-300.

A case with such a value must be refused (exit 2), run (exit 0) or fail with a
solver's own message (exit 1): never a hang, a signal, or a protocol error
(a solver offering the coupler a value the wire refuses, as the fluid's CFL
step of 0 and the solid's READY dt = 0 did). This sweep found: intervals of
1e-300 s that hung the solid and a solid-only coupler (SIGINT and SIGTERM
unheard), a standalone solid that "finished" at once with exit 0 when its
step count overflowed, and keys whose absurd values ran into NaN or a
non-finite PPE (docs/security.md, "Broken case files").

The key lists are written out below, each key in a case that has it; every
number key the programs list (`PROGRAM --keys`) must be in one of them, so a
key added to a program without being added here fails this test.

usage: sweep_numbers.py BIN_DIR [--jobs N] [--deadline S]
"""
import argparse
import concurrent.futures
import fnmatch
import os
import re
import signal
import subprocess
import sys
import tempfile

VALUES = ['0', '-1e300', '1e300', '1e-300']

COMMON = ['dp', 'end_time', 'gravity.x', 'gravity.y', 'output.interval',
          'output.probe_interval', 'output.checkpoint_interval']
FLUID = ['fluid.rho', 'fluid.nu', 'fluid.courant', 'fluid.dt_max', 'fluid.dt_min',
         'fluid.kappa', 'fluid.kappa_dt', 'fluid.kappa_step_decay',
         'fluid.kappa_step_decay_expansion', 'fluid.density_dead_band',
         'fluid.divergence_floor', 'fluid.gradient_floor', 'fluid.alpha', 'fluid.re_n',
         'fluid.re_lap', 'fluid.beta1', 'fluid.beta2', 'fluid.surface_scan',
         'fluid.surface_scan_density', 'fluid.tension_solves', 'fluid.tension_sweeps',
         'fluid.collision_distance',
         'fluid.collision_restitution', 'fluid.jitter.amplitude', 'fluid.jitter.seed',
         'fluid.shifting', 'fluid.shifting_max', 'fluid.ppe_max_iter', 'fluid.ppe_drop',
         'fluid.ppe_coarse_cell', 'fluid.ppe_rtol', 'fluid.tank.width', 'fluid.tank.height',
         'fluid.tank.wall_layers', 'fluid.droplet_neighbours', 'fluid.blocks.0.x0',
         'fluid.blocks.0.y0', 'fluid.blocks.0.x1', 'fluid.blocks.0.y1', 'fluid.probes.0.x',
         'fluid.probes.0.y']
SOLID = ['solid.courant', 'solid.plane_factor', 'solid.refine', 'solid.mps.damping',
         'solid.tlsph.alpha', 'solid.tlsph.hourglass', 'solid.interface_depth', 'solid.eps_max',
         'solid.bodies.0.x0', 'solid.bodies.0.y0', 'solid.bodies.0.x1', 'solid.bodies.0.y1',
         'solid.bodies.0.rho', 'solid.bodies.0.E', 'solid.bodies.0.nu', 'solid.bodies.0.vx',
         'solid.bodies.0.vy', 'solid.clamps.0.x0', 'solid.clamps.0.y0', 'solid.clamps.0.x1',
         'solid.clamps.0.y1', 'solid.probes.0.x', 'solid.probes.0.y']
COUPLING = ['coupling.hello_timeout', 'coupling.ready_timeout', 'coupling.step_timeout',
            'coupling.tcp_port',
            'coupling.implicit.relaxation', 'coupling.implicit.tolerance',
            'coupling.implicit.abs_tolerance', 'coupling.implicit.max_iterations',
            'coupling.implicit.reuse', 'coupling.implicit.filter']
MOTION = ['motion.angle', 'motion.amplitude', 'motion.pivot.x', 'motion.pivot.y',
          'fluid.side_walls.breadth', 'fluid.side_walls.period']

# (program, case, settings that make it short, keys): each run is well under a
# second on two cores when it runs at all
RUNS = [
    ('coupler', 'cases/dambreak_elastic_plate/case.yml', ['dp=0.006', 'end_time=0.02'],
     COMMON + FLUID + SOLID + COUPLING),
    ('coupler', 'tests/coupler/plate_in_water.yml',
     ['end_time=0.01', 'coupling.scheme=implicit'], COUPLING),
    ('fluid_solver', 'cases/dambreak/case.yml', ['dp=0.008', 'end_time=0.02'], COMMON + FLUID),
    ('solid_solver', 'cases/cantilever_beam/case.yml', ['end_time=0.002'], COMMON + SOLID),
    ('solid_solver', 'cases/fracture_collision/case.yml', ['end_time=0.0005'],
     COMMON + ['solid.eps_max', 'solid.bodies.0.vx', 'solid.bodies.0.E']),
    ('solid_solver', 'cases/cantilever_beam/case.yml',
     ['end_time=0.002', 'solid.model=tlsph'], ['solid.tlsph.alpha', 'solid.tlsph.hourglass']),
    ('coupler', 'cases/sloshing_low/case.yml', ['dp=0.004', 'end_time=0.01'], MOTION),
    ('coupler', 'cases/sloshing_high/case.yml', ['dp=0.004', 'end_time=0.01', 'motion.kind=table'],
     ['motion.table.scale', 'motion.table.knot_spacing']),
    # the dam break's fifth probe is its wall's pressure transducer
    ('fluid_solver', 'cases/dambreak/case.yml', ['dp=0.008', 'end_time=0.02'],
     ['fluid.probes.4.diameter']),
    # the coupler's own event loop, with a solid alone
    ('coupler', 'cases/cantilever_beam/case.yml', ['end_time=0.002'], COMMON),
]
DEADLINE = 30  # s: a hang is what is looked for, and a run of these takes < 2 s


def one(bin_dir, out_root, deadline, prog, case, base, key, value):
    tag = f'{prog} {case} {key}={value}'
    out = os.path.join(out_root, f'{prog}-{os.path.basename(os.path.dirname(case))}-{key}={value}')
    cmd = [os.path.join(bin_dir, prog), case, '--out', out, '--quiet']
    for s in base + [f'{key}={value}']:
        cmd += ['--set', s]
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                         errors='replace', start_new_session=True)
    try:
        _, err = p.communicate(timeout=deadline)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)  # its solvers too
        p.communicate()
        return tag, f'no end within {deadline} s (killed)'
    last = err.strip().splitlines()[-1] if err.strip() else ''
    if p.returncode < 0:
        return tag, f'killed by signal {-p.returncode}: {last}'
    if p.returncode not in (0, 1, 2):
        return tag, f'exit {p.returncode}: {last}'
    if p.returncode and not last:
        return tag, f'exit {p.returncode} with nothing on stderr'
    if 'protocol:' in err:
        return tag, f'a protocol error from a case value: {last}'
    # a sanitizer build's reports (build-debug): UBSan goes on after its line
    for line in err.splitlines():
        if 'runtime error:' in line or 'Sanitizer' in line:
            return tag, f'sanitizer: {line.strip()[:300]}'
    return tag, None


def unswept(bin_dir):
    """The number keys some program lists (--keys) that no run sweeps; a
    list item's key ("fluid.blocks.*.x0") is swept by any item's."""
    swept = {key for _, _, _, keys in RUNS for key in keys}
    listed = set()
    for prog in ('coupler', 'fluid_solver', 'solid_solver'):
        p = subprocess.run([os.path.join(bin_dir, prog), '--keys'], capture_output=True,
                           text=True, timeout=60)
        if p.returncode != 0:
            sys.exit(f'sweep_numbers: {prog} --keys: exit {p.returncode}: {p.stderr.strip()}')
        listed |= set(re.findall(r'^- `([^`]+)` \((?:number|integer)\b', p.stdout, re.M))
    if not listed:
        sys.exit('sweep_numbers: no number key in the programs\' --keys lists')
    return sorted(k for k in listed
                  if not any(fnmatch.fnmatchcase(s, k.replace('*', '[0-9]*')) for s in swept))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('bin_dir')
    ap.add_argument('--jobs', type=int, default=2)
    ap.add_argument('--deadline', type=float, default=DEADLINE,
                    help='seconds a run may take (more for a sanitizer build)')
    a = ap.parse_args()
    missing = unswept(a.bin_dir)
    if missing:
        print(f'FAIL  number keys the programs list that no run here sweeps: '
              f'{", ".join(missing)}: add each to a run of a case that has it')
        return 1
    out_root = tempfile.mkdtemp(prefix='sweep_numbers_')
    jobs = [(prog, case, base, key, v) for prog, case, base, keys in RUNS
            for key in keys for v in VALUES]
    bad = []
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as ex:
        for tag, why in ex.map(lambda j: one(a.bin_dir, out_root, a.deadline, *j), jobs):
            if why:
                bad.append(tag)
                print(f'FAIL  {tag}: {why}')
    print(f'{len(jobs)} runs: {len(jobs) - len(bad)} passed, {len(bad)} failed')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
