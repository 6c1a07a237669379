#!/usr/bin/python3
"""Coupler integration tests: a three-process run with a fake solid, and
every failure the coupler must handle without hanging.

usage: test_coupler.py BUILD_BIN_DIR TEST_NAME
Each test prints what it checked and exits non-zero on failure."""
import csv, glob, json, os, signal, subprocess, sys, tempfile, time

import h5py

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from host_expect import expected_host  # noqa: E402

BIN = os.path.abspath(sys.argv[1])
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, 'tests', 'coupler', 'plate_in_water.yml')
COUPLER = os.path.join(BIN, 'coupler')
failures = []


def check(cond, what):
    print(('ok    ' if cond else 'FAIL  ') + what)
    if not cond:
        failures.append(what)


def run(args, timeout=120, **kw):
    p = subprocess.run([COUPLER] + args, capture_output=True, text=True, timeout=timeout, **kw)
    return p.returncode, p.stderr


def probes(out):
    with open(os.path.join(out, 'probes.csv')) as f:
        return list(csv.DictReader(f))


def solver_pids(out):
    with open(os.path.join(out, 'summary.json')) as f:
        s = json.load(f)
    return [v['pid'] for v in s['solvers'].values() if v.get('pid')]


def gone(pid):
    try:
        os.kill(pid, 0)
        return False
    except ProcessLookupError:
        return True


def h5_readable(out):
    files = sorted(glob.glob(os.path.join(out, '*.h5')))
    for f in files:
        with h5py.File(f, 'r') as h:
            h['particles/position'][:]
    return len(files)


def after_failure(out, rc, err, pattern, code=None):
    check(rc != 0 if code is None else rc == code, f'exit status {rc} (expected {"non-zero" if code is None else code})')
    check(pattern in err, f'stderr names the cause: {pattern!r}')
    pids = solver_pids(out)
    check(all(gone(p) for p in pids), f'no solver left running ({pids})')
    try:
        n = h5_readable(out)
        check(n >= 1, f'{n} HDF5 snapshots written so far are readable')
    except Exception as e:  # noqa: BLE001
        check(False, f'HDF5 readable: {e}')


def t_plate_force():
    """Still water against a rigid plate: the fluid's loads (Eq. 50-51) must
    add up to the hydrostatic force rho g h^2 / 2 = 196.2 N/m (h = 0.2 m).
    The top particle layer is the free surface (P = 0 at its centres, dp/2
    below the water line), which puts the discrete force at
    rho g (h - dp/2)^2 / 2 = 186.5 N/m: the band [0.93, 1.05] x 196.2 covers
    both readings and the MPS pressure noise."""
    out = tempfile.mkdtemp(prefix='cpl_plate_')
    rc, err = run([SCENE, '--out', out, '--quiet', '--solid', 'fake_solid', '--set', 'end_time=0.4'])
    check(rc == 0, f'coupled run exits 0 ({err.strip()[-200:]})')
    rows = [r for r in probes(out) if float(r['time']) >= 0.1]
    fx = sum(float(r['plate_fx']) for r in rows) / len(rows)
    exact = 1000 * 9.81 * 0.2 ** 2 / 2
    check(0.93 * exact <= fx <= 1.05 * exact, f'mean plate force {fx:.1f} N/m vs rho g h^2/2 = {exact:.1f}')
    # the coupler's own column: the same loads, averaged over each probe
    # interval instead of sampled at its end (3%: the sampled column's noise)
    cfx = sum(float(r['solid_fx']) for r in rows) / len(rows)
    check(abs(cfx - fx) <= 0.03 * exact, f'coupler solid_fx {cfx:.1f} N/m vs the solid\'s plate_fx {fx:.1f}')
    # tip_EI: the loads' quasi-static cantilever tip deflection times E I,
    # sum f a^2 (3L - a) / 6 (clamp top at 0.02 m, L = 0.28 m): for the
    # hydrostatic load of the same free surface (dp/2 below the water line)
    # int_0^(h - dp/2 - 0.02) rho g (h - dp/2 - 0.02 - a) a^2 (3L - a) / 6 da.
    # Measured 0.1005 against 0.0936 N m^2 (+7%, the force +2%): the fluid's
    # pressure is above rho g depth in the top rows, which the height
    # weighting stresses. Band [0.95, 1.12] x the hydrostatic value.
    ei = sum(float(r['tip_EI']) for r in rows) / len(rows)
    hh, L = 0.2 - 0.005 - 0.02, 0.28
    a = [hh * (k + 0.5) / 2000 for k in range(2000)]
    want = sum(1000 * 9.81 * (hh - x) * x * x * (3 * L - x) / 6 for x in a) * hh / 2000
    check(0.95 * want <= ei <= 1.12 * want, f'tip_EI {ei:.4f} N m^2 vs hydrostatic {want:.4f}')
    s = json.load(open(os.path.join(out, 'summary.json')))
    check(s['status'] == 'ok', 'summary status ok')
    check(s['solvers']['solid']['exchanges'] == s['coupling_steps'], 'one solid exchange per fluid step')
    check(os.path.exists(os.path.join(out, 'scene.xmf')), 'scene.xmf written')
    # timings are a property of the machine: each summary names it
    fs = json.load(open(os.path.join(out, 'fluid_summary.json')))
    for name, summary in (('coupler', s), ('fluid', fs)):
        check(summary.get('host') == expected_host(),
              f"{name} summary names the host: {summary.get('host')!r}")


def t_moving_plate():
    """A plate oscillating on a prescribed path pushes water: the force on it
    must vary with the motion, and the fluid must not leak through it."""
    out = tempfile.mkdtemp(prefix='cpl_move_')
    rc, err = run([SCENE, '--out', out, '--quiet', '--solid', 'fake_solid --amplitude 0.01 --frequency 4',
                   '--set', 'end_time=0.3'])
    check(rc == 0, f'coupled run with a moving plate exits 0 ({err.strip()[-200:]})')
    rows = probes(out)
    dx = [float(r['plate_dx']) for r in rows]
    fx = [float(r['plate_fx']) for r in rows if float(r['time']) > 0.05]
    check(max(dx) > 0.009 and min(dx) < -0.009, f'plate followed its path (dx in [{min(dx):.4f}, {max(dx):.4f}])')
    check(max(fx) - min(fx) > 20.0, f'load responds to the motion (fx range {min(fx):.0f}..{max(fx):.0f} N/m)')


def t_solid_crash():
    out = tempfile.mkdtemp(prefix='cpl_crash_')
    rc, err = run([SCENE, '--out', out, '--quiet', '--solid', 'fake_solid --fail-at 0.03'])
    after_failure(out, rc, err, 'solid solver was killed by signal 6')


def t_solid_hang():
    out = tempfile.mkdtemp(prefix='cpl_hang_')
    t0 = time.time()
    rc, err = run([SCENE, '--out', out, '--quiet', '--solid', 'fake_solid --hang-at 0.03',
                   '--set', 'coupling.step_timeout=2'])
    after_failure(out, rc, err, 'solid solver did not answer within 2 s')
    check(time.time() - t0 < 30, 'the hang is noticed at the deadline')


def kill_mid_run(which, prefix):
    """Starts a long run with the fake solid, SIGKILLs the coupler's child
    whose command line holds `which` once the run steps, and returns
    (out, returncode, stderr, seconds from the kill to the coupler's exit)."""
    out = tempfile.mkdtemp(prefix=prefix)
    # long enough that it is still running when we strike
    p = subprocess.Popen([COUPLER, SCENE, '--out', out, '--quiet', '--solid', 'fake_solid',
                          '--set', 'end_time=20'], stderr=subprocess.PIPE, text=True)
    pid = None
    for _ in range(300):
        time.sleep(0.1)
        if os.path.exists(os.path.join(out, 'probes.csv')) and len(probes(out)) > 3:
            break
    kids = subprocess.run(['pgrep', '-P', str(p.pid)], capture_output=True, text=True).stdout.split()
    for k in kids:
        with open(f'/proc/{k}/cmdline', 'rb') as f:
            if which in f.read():
                pid = int(k)
    check(pid is not None, f'found the running {which.decode()}')
    t0 = time.time()
    if pid:
        os.kill(pid, signal.SIGKILL)
    err = p.communicate(timeout=60)[1]
    return out, p.returncode, err, time.time() - t0


def t_fluid_killed():
    out, rc, err, _ = kill_mid_run(b'fluid_solver', 'cpl_kill_')
    after_failure(out, rc, err, 'fluid solver was killed by signal 9')


def t_solid_killed():
    """The solid idles while the fluid steps, so it dies between exchanges:
    the coupler must name it when it next sends, not wait out the link's
    10 s send timeout."""
    out, rc, err, waited = kill_mid_run(b'fake_solid', 'cpl_skill_')
    after_failure(out, rc, err, 'solid solver was killed by signal 9')
    check(waited < 5.0, f'noticed {waited:.1f} s after the kill (send timeout: 10 s)')


def t_interrupt():
    out = tempfile.mkdtemp(prefix='cpl_int_')
    # long enough that it is still running when we strike
    p = subprocess.Popen([COUPLER, SCENE, '--out', out, '--quiet', '--solid', 'fake_solid',
                          '--set', 'end_time=20'], stderr=subprocess.PIPE, text=True)
    for _ in range(300):
        time.sleep(0.1)
        if os.path.exists(os.path.join(out, 'probes.csv')) and len(probes(out)) > 3:
            break
    p.send_signal(signal.SIGINT)
    err = p.communicate(timeout=60)[1]
    after_failure(out, p.returncode, err, 'interrupted', code=130)


def t_fluid_fails():
    """A fluid that fails (here its PPE solver is starved of iterations)
    reports ERROR; the coupler names it and the reason."""
    out = tempfile.mkdtemp(prefix='cpl_ffail_')
    rc, err = run([SCENE, '--out', out, '--quiet', '--solid', 'fake_solid',
                   '--set', 'fluid.ppe_max_iter=1', '--set', 'fluid.ppe_rtol=1e-14',
                   '--set', 'fluid.ppe_solver=pcg_jacobi'])
    after_failure(out, rc, err, 'fluid solver: solver:')


def t_wrong_version():
    out = tempfile.mkdtemp(prefix='cpl_ver_')
    report = os.path.join(out, 'solver_report.txt')
    solver = os.path.join(ROOT, 'tests', 'coupler', 'bad_version_solver.py')
    rc, err = run([SCENE, '--out', out, '--quiet', '--solid', f'/usr/bin/python3 {solver} {report}'])
    check(rc != 0, f'coupler refuses the solver (exit {rc})')
    check('protocol version 1 received, this build speaks version 2' in err,
          'coupler says which versions')
    told = open(report).read() if os.path.exists(report) else ''
    check(told.startswith('REJECT') and 'version 1' in told, f'solver was told: {told.strip()}')


def t_no_rollback():
    """Implicit coupling repeats steps: a solid that does not declare
    caps=rollback in HELLO is refused at the handshake (exit 2, the reason on
    stderr and in its REJECT), nothing is stepped; the same solver runs
    explicit."""
    for solid in ('fake_solid --no-rollback',
                  f'/usr/bin/python3 {ROOT}/tests/coupler/conformance_toy_solid.py'):
        out = tempfile.mkdtemp(prefix='cpl_noroll_')
        rc, err = run([SCENE, '--out', out, '--quiet', '--solid', solid,
                       '--set', 'coupling.scheme=implicit', '--set', 'end_time=0.01'])
        check(rc == 2, f'{solid}: implicit refused with exit 2 (got {rc})')
        check('caps=rollback' in err and 'solid' in err,
              f'{solid}: the coupler says why: {err.strip().splitlines()[-1] if err.strip() else ""}')
        s = json.load(open(os.path.join(out, 'summary.json')))
        check(s['coupling_steps'] == 0 and s['failed_solver'] == 'solid',
              f'{solid}: no step taken, the solid named ({s["coupling_steps"]}, {s["failed_solver"]})')
    out = tempfile.mkdtemp(prefix='cpl_noroll_')
    rc, err = run([SCENE, '--out', out, '--quiet', '--solid', 'fake_solid --no-rollback',
                   '--set', 'end_time=0.01'])
    check(rc == 0, f'the same solid runs explicit (exit {rc}) {err.strip()[-200:]}')
    # what the solvers cannot roll back: fracture (the coupler refuses the
    # case, naming the key) and a PPE solver with a history (the fluid
    # refuses rollback=on with an input ERROR before READY)
    for sets, what in ((['solid.eps_max=0.1'], 'coupling.scheme'),
                       (['fluid.ppe_solver=cholmod_reuse'], 'cholmod_reuse')):
        out = tempfile.mkdtemp(prefix='cpl_noroll_')
        args = [SCENE, '--out', out, '--quiet', '--set', 'coupling.scheme=implicit',
                '--set', 'end_time=0.01']
        for x in sets:
            args += ['--set', x]
        rc, err = run(args)
        line = err.strip().splitlines()[0] if err.strip() else ''
        check(rc == 2 and what in err, f'{sets[0]} with implicit coupling: exit {rc}, {line[:200]}')


def t_implicit_fake():
    """Implicit coupling with the fake solid (a rigid plate on a prescribed
    path: its state does not depend on the loads, so the fixed point is its
    path and every step converges): the run ends, every step took at least one
    and at most a few iterations, the summary counts them, and the force the
    fake solid received is the explicit run's within the load noise."""
    res = {}
    for scheme in ('explicit', 'implicit'):
        out = tempfile.mkdtemp(prefix=f'cpl_{scheme}_')
        rc, err = run([SCENE, '--out', out, '--quiet', '--solid',
                       'fake_solid --amplitude 0.002 --frequency 2', '--set', f'coupling.scheme={scheme}',
                       '--set', 'end_time=0.2'])
        check(rc == 0, f'{scheme}: exit {rc} {err.strip()[-300:]}')
        res[scheme] = (json.load(open(os.path.join(out, 'summary.json'))), probes(out))
    s = res['implicit'][0]
    it = s.get('iterations', {})
    check(it.get('scheme') == 'implicit' and it.get('steps') == s['coupling_steps'],
          f'summary counts the implicit steps: {it}')
    check(1 <= it.get('max', 0) <= 6 and it.get('mean', 0) >= 1.0 and it.get('limit_hits') == 0,
          f'iterations per step: mean {it.get("mean")}, max {it.get("max")}, limit hits {it.get("limit_hits")}')
    e = res['explicit'][0]['iterations']
    check(e.get('mean') == 1.0 and e.get('max') == 1, f'explicit: one iteration per step ({e})')


def cpus_allowed(pid, tid=None):
    """The CPUs a thread may run on, from /proc."""
    path = f'/proc/{pid}/task/{tid or pid}/status'
    with open(path) as f:
        line = next(l for l in f if l.startswith('Cpus_allowed_list:'))
    cpus = set()
    for part in line.split(':', 1)[1].strip().split(','):
        lo, _, hi = part.partition('-')
        cpus.update(range(int(lo), int(hi or lo) + 1))
    return cpus


def placement_while_running(extra):
    """Starts a long coupled run, and once it steps reads where the coupler
    and the fluid's threads may run; then stops it with SIGTERM."""
    out = tempfile.mkdtemp(prefix='cpl_cpu_')
    env = {k: v for k, v in os.environ.items() if k not in ('OMP_PLACES', 'OMP_PROC_BIND')}
    env['OMP_NUM_THREADS'] = '2'
    p = subprocess.Popen([COUPLER, SCENE, '--out', out, '--quiet', '--solid', 'fake_solid',
                          '--set', 'end_time=20'] + extra, stderr=subprocess.PIPE, text=True,
                         env=env)
    for _ in range(300):
        time.sleep(0.1)
        if os.path.exists(os.path.join(out, 'probes.csv')) and len(probes(out)) > 3:
            break
    fluid = None
    for k in subprocess.run(['pgrep', '-P', str(p.pid)], capture_output=True,
                            text=True).stdout.split():
        with open(f'/proc/{k}/cmdline', 'rb') as f:
            if b'fluid_solver' in f.read():
                fluid = int(k)
    seen = {'coupler': cpus_allowed(p.pid)}
    if fluid:
        seen['fluid_main'] = cpus_allowed(fluid)
        seen['fluid_others'] = [cpus_allowed(fluid, int(t)) for t in os.listdir(f'/proc/{fluid}/task')
                                if int(t) != fluid]
    p.send_signal(signal.SIGTERM)
    p.communicate(timeout=60)
    s = json.load(open(os.path.join(out, 'summary.json')))
    return seen, s.get('cpu_placement', '')


def t_cpu_placement():
    """coupling.pin_cpus: auto puts the coupler and the fluid's main thread on
    one CPU (messages then cost a context switch, not a wake-up on another
    CPU: bench/zmq_roundtrip.c) and leaves the fluid's other threads (OpenMP
    workers, ZeroMQ's) free to use every CPU or bound elsewhere; off leaves
    everything on every CPU."""
    allowed = os.sched_getaffinity(0)
    if len(allowed) < 2:
        print('one CPU: nothing to place')
        return
    seen, note = placement_while_running([])
    check(len(seen['coupler']) == 1, f'auto: coupler on one CPU ({sorted(seen["coupler"])})')
    check(seen.get('fluid_main') == seen['coupler'],
          f'auto: fluid main thread on the same CPU ({sorted(seen.get("fluid_main", []))})')
    others = seen.get('fluid_others', [])
    check(any(o - seen['coupler'] for o in others),
          f'auto: some fluid thread (an OpenMP worker) may run on another CPU ({[sorted(o) for o in others]})')
    check('shared' in note, f'summary says what was done: {note!r}')
    seen, note = placement_while_running(['--set', 'coupling.pin_cpus=off'])
    check(seen['coupler'] == allowed and seen.get('fluid_main') == allowed,
          f'off: coupler and fluid on every CPU ({sorted(seen["coupler"])}, {sorted(seen.get("fluid_main", []))})')
    check(note.startswith('off'), f'summary says off: {note!r}')


TESTS = {k[2:]: v for k, v in globals().items() if k.startswith('t_')}

if __name__ == '__main__':
    name = sys.argv[2]
    TESTS[name]()
    print(f'{name}: {len(failures)} failed')
    sys.exit(1 if failures else 0)
