#!/usr/bin/python3
"""A third-party solid: an elastic plate as a cantilever beam in its first
bending mode, written in Python against proto/PROTOCOL.md only (numpy, pyzmq,
PyYAML, h5py from Debian; the wire codec is proto/python/mpsproto.py, itself
written from PROTOCOL.md). It proves a solver in another language can replace
ours.

Model (Euler-Bernoulli, per metre depth): the first body of the case is a
vertical plate of thickness b = x1 - x0 clamped where a solid.clamps region
covers it (its top edge is the root); above the root, the lateral displacement
is u(s, t) = q(t) phi(s), s the height above the root, phi the first cantilever
mode normalised to phi(L) = 1. Then M q'' + K q = F with M = rho b int phi^2,
K = E b^3/12 int phi''^2 (= omega_1^2 M) and F = sum_k f_x,k phi(s_k), the
generalised force of the fluid loads. q is the tip deflection (probe tip_dx).

Snapshots (at startup and after an ADVANCE with SNAPSHOT) are HDF5 files
OUT/PREFIX_NNNNNN.h5, NNNNNN counting snapshots, with an XDMF index
OUT/PREFIX.xmf in the layout the C solvers write (docs/output.md), so the
coupler's scene.xmf shows the plate with the fluid. Failures are reported to
the coupler as ERROR (PROTOCOL.md 8). tests/coupler/conformance.py checks it
against the protocol.

Implicit coupling (PROTOCOL.md 6): it declares caps=rollback; with rollback=on
in CONFIG it keeps (q, q') and the number of snapshots at the start of every
step and returns to them when the coupler repeats the step (a repeated
snapshot is written again under the same name and listed once in the index).

Checkpoints (PROTOCOL.md 6, docs/restart.md): it declares caps=checkpoint;
after an ADVANCE with CHECKPOINT it writes OUT/checkpoint/PREFIX_NNNNNN.ckpt
(its own format: JSON with q, q', the step count and the snapshot index, the
floats as hex so they read back bit for bit; written to a temporary file and
renamed; the last two kept), NNNNNN counting the checkpoints from CONFIG
restart=N (or 0); with restart=N in CONFIG it starts from checkpoint N.

usage: modal_beam_solid.py [--courant C] [--key FILE] --connect ENDPOINT
"""
import hashlib, json, math, os, sys, time

import h5py
import numpy as np
import zmq

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'proto',
                                'python'))
import mpsproto as mp  # noqa: E402

BETA_L = 1.8751040687119611  # first root of cos(x) cosh(x) = -1


def mode(s, L):
    """First cantilever mode and its second derivative, phi(L) = 1."""
    b = BETA_L / L
    sig = (math.cosh(BETA_L) + math.cos(BETA_L)) / (math.sinh(BETA_L) + math.sin(BETA_L))
    def raw(x):
        return np.cosh(b * x) - np.cos(b * x) - sig * (np.sinh(b * x) - np.sin(b * x))
    def raw2(x):
        return b * b * (np.cosh(b * x) + np.cos(b * x) - sig * (np.sinh(b * x) + np.sin(b * x)))
    tip = raw(L)
    s = np.clip(s, 0.0, L)
    return raw(s) / tip, raw2(s) / tip


# Its own keys, which no other program knows (PROTOCOL.md 4: the solid's
# section is the solid's): the coupler hands them over unread.
OWN_KEYS = {'solid.modal_beam.courant': 'fraction of the stable step 2/omega_1 / 10 '
                                        '(default: --courant, 0.5)'}


class Beam:
    def __init__(self, case, courant):
        """case: an mp.Case. Each key this solid reads is checked here, and a
        wrong one raises mp.CaseError naming where it was given."""
        case.only('solid.modal_beam.', OWN_KEYS)
        courant = case.number('solid.modal_beam.courant', courant, lo=0.0, lo_open=True, hi=1.0)
        dp = case.number('dp', lo=0.0, lo_open=True)
        nb = case.count('solid.bodies')
        if nb == 0:
            raise mp.CaseError(f'{case.file}: solid.bodies: no solid body given')
        if nb > 1:  # not silently dropped
            case.fail('solid.bodies.1.name' if case.has('solid.bodies.1.name') else
                      'solid.bodies.1', 'the modal beam solid models one body')
        b = 'solid.bodies.0'
        x0, y0, x1, y1 = (case.number(f'{b}.{k}') for k in ('x0', 'y0', 'x1', 'y1'))
        if x1 <= x0:
            case.fail(f'{b}.x1', f'must be > x0 = {x0:g}')
        if y1 <= y0:
            case.fail(f'{b}.y1', f'must be > y0 = {y0:g}')
        rho = case.number(f'{b}.rho', lo=0.0, lo_open=True)
        E = case.number(f'{b}.E', lo=0.0, lo_open=True)
        # the 3D strip's bending stiffness over the 2D plane's (solid.plane_factor,
        # as the C solids read it)
        E *= case.number('solid.plane_factor', 1.0, lo=0.0, lo_open=True, hi=2.0)
        clamp_tops = [case.number(f'solid.clamps.{k}.y1') for k in range(case.count('solid.clamps'))]
        root = max(clamp_tops + [y0])
        if root >= y1:
            case.fail(f'solid.clamps.{clamp_tops.index(root)}.y1',
                      'the clamp covers the whole plate: nothing is left to bend')
        nx, ny = int(math.floor((x1 - x0) / dp + 1e-6)), int(math.floor((y1 - y0) / dp + 1e-6))
        ii, jj = np.meshgrid(np.arange(nx), np.arange(ny))
        self.x0 = np.column_stack([x0 + (ii.ravel() + 0.5) * dp, y0 + (jj.ravel() + 0.5) * dp])
        self.n = len(self.x0)
        self.id = np.arange(self.n, dtype=np.int32)
        self.fixed = (self.x0[:, 1] < root).astype(np.uint8)
        edge = (ii.ravel() == 0) | (ii.ravel() == nx - 1) | (jj.ravel() == 0) | (jj.ravel() == ny - 1)
        self.surface = edge.astype(np.uint8)
        self.L = y1 - root
        b = x1 - x0
        s = np.linspace(0.0, self.L, 2001)
        phi, phi2 = mode(s, self.L)
        self.M = rho * b * np.trapz(phi ** 2, s)
        self.K = E * b ** 3 / 12.0 * np.trapz(phi2 ** 2, s)
        self.omega = math.sqrt(self.K / self.M)
        self.phi, _ = mode(self.x0[:, 1] - root, self.L)
        self.phi[self.fixed == 1] = 0.0
        self.dt = courant * 2.0 / self.omega / 10.0  # well inside the symplectic limit 2/omega
        self.q = self.qd = 0.0
        self.force = 0.0

    def state(self):
        x = self.x0.copy()
        x[:, 0] += self.q * self.phi
        v = np.zeros_like(x)
        v[:, 0] = self.qd * self.phi
        return x, v

    def advance(self, h, n):
        for _ in range(n):  # symplectic Euler, as the MPS solid
            self.qd += h * (self.force - self.K * self.q) / self.M
            self.q += h * self.qd


class Fail(Exception):
    """A failure to report as ERROR "STATUS: message" (PROTOCOL.md section 8)."""

    def __init__(self, status, message):
        super().__init__(f'{status}: {message}')


class Snapshots:
    """OUT/PREFIX_NNNNNN.h5 and the index OUT/PREFIX.xmf, as common/mps_h5.c
    writes them (vectors with 3 components, z = 0; the index one element per
    line, rewritten through a temporary file, so the coupler's scene.xmf can
    take its grids). The protocol asks for a snapshot at startup and after an
    ADVANCE with SNAPSHOT; the format is the solver's own."""

    def __init__(self, out, prefix, config_text):
        self.out, self.prefix, self.config = out, prefix, config_text
        self.grids = []

    def write(self, step, t, beam):
        x, v = beam.state()
        n = len(x)
        pad = lambda a: np.column_stack([a, np.zeros(n)])  # noqa: E731
        name = f'{self.prefix}_{len(self.grids):06d}'
        path = os.path.join(self.out, name + '.h5')
        fields = [('velocity', pad(v), 'm/s'), ('displacement', pad(x - beam.x0), 'm'),
                  ('id', beam.id, ''), ('surface', beam.surface, ''), ('fixed', beam.fixed, '')]
        legends = {'surface': '1 on the plate\'s edge (given to the fluid), 0 inside',
                   'fixed': '1 clamped (never moves), 0 free'}
        try:
            with h5py.File(path + '.tmp', 'w') as h:
                h.attrs['time'] = float(t)
                h.attrs['step'] = np.int64(step)
                h.attrs['solver'] = 'modal_beam_solid'
                h['config'] = self.config
                h['topology'] = np.arange(n, dtype=np.int32)  # Polyvertex connectivity
                g = h.create_group('particles')
                g['position'] = pad(x)
                g['position'].attrs['units'] = 'm'
                for fname, data, units in fields:
                    g[fname] = data
                    g[fname].attrs['units'] = units
                    if fname in legends:
                        g[fname].attrs['legend'] = legends[fname]
            os.replace(path + '.tmp', path)
        except OSError as e:
            raise Fail('io', f'cannot write {path}: {e}') from e
        item = lambda what, dims, num: (  # noqa: E731
            f'     <DataItem Dimensions="{dims}" {num} Format="HDF">{name}.h5:/particles/{what}'
            '</DataItem>\n')
        f64, i32, u8 = ('NumberType="Float" Precision="8"', 'NumberType="Int" Precision="4"',
                        'NumberType="UChar" Precision="1"')
        grid = (f'   <Grid Name="{name}" GridType="Uniform">\n'
                f'    <Time Value="{t!r}"/>\n'
                f'    <Topology TopologyType="Polyvertex" NumberOfElements="{n}" NodesPerElement="1">\n'
                f'     <DataItem Dimensions="{n}" {i32} Format="HDF">{name}.h5:/topology</DataItem>\n'
                '    </Topology>\n'
                '    <Geometry GeometryType="XYZ">\n' + item('position', f'{n} 3', f64) +
                '    </Geometry>\n')
        for fname, data, _ in fields:
            vec = data.ndim == 2
            num = f64 if data.dtype == np.float64 else i32 if data.dtype == np.int32 else u8
            grid += (f'    <Attribute Name="{fname}" AttributeType="{"Vector" if vec else "Scalar"}" '
                     'Center="Node">\n' + item(fname, f'{n} 3' if vec else f'{n}', num) +
                     '    </Attribute>\n')
        self.grids.append(grid + '   </Grid>\n')
        self.index()

    def index(self):
        """Rewrites OUT/PREFIX.xmf from the grids (after a snapshot, a restart)."""
        index = os.path.join(self.out, self.prefix + '.xmf')
        try:
            with open(index + '.tmp', 'w') as f:
                f.write('<?xml version="1.0" ?>\n<Xdmf Version="2.0">\n <Domain>\n'
                        f'  <Grid Name="{self.prefix}" GridType="Collection" CollectionType="Temporal">\n')
                f.writelines(self.grids)
                f.write('  </Grid>\n </Domain>\n</Xdmf>\n')
            os.replace(index + '.tmp', index)
        except OSError as e:
            raise Fail('io', f'cannot write {index}: {e}') from e


class Checkpoints:
    """OUT/checkpoint/PREFIX_NNNNNN.ckpt: the beam's whole state (q, q') with
    the step count and the snapshot index (the series continues from it), as
    JSON after a line with its SHA-256: a damaged file is refused, not read as
    another state (the C solvers' checkpoints carry a hash too)."""

    def __init__(self, out, prefix):
        self.dir, self.prefix = os.path.join(out, 'checkpoint'), prefix

    def path(self, number):
        return os.path.join(self.dir, f'{self.prefix}_{number:06d}.ckpt')

    def write(self, number, t, beam, step, grids):
        state = {'number': number, 'time': float(t).hex(), 'q': float(beam.q).hex(),
                 'qd': float(beam.qd).hex(), 'step': step, 'grids': grids}
        path = self.path(number)
        try:
            os.makedirs(self.dir, exist_ok=True)
            body = json.dumps(state)
            with open(path + '.tmp', 'w') as f:  # the body's SHA-256 on the first line
                f.write(hashlib.sha256(body.encode()).hexdigest() + '\n' + body)
                f.flush()
                os.fsync(f.fileno())
            os.replace(path + '.tmp', path)  # a kill while writing leaves the last ones
            for name in os.listdir(self.dir):  # keep this one and the one before
                if name.startswith(self.prefix + '_') and name.endswith('.ckpt'):
                    k = name[len(self.prefix) + 1:-5]
                    if k.isdigit() and (int(k) <= number - 2 or int(k) > number):
                        os.remove(os.path.join(self.dir, name))
        except OSError as e:
            raise Fail('io', f'cannot write {path}: {e}') from e

    def read(self, number, beam):
        path = self.path(number)
        try:
            with open(path) as f:
                digest, _, body = f.read().partition('\n')
            if hashlib.sha256(body.encode()).hexdigest() != digest:
                raise ValueError('checkpoint damaged (SHA-256 mismatch)')
            state = json.loads(body)
            beam.q, beam.qd = float.fromhex(state['q']), float.fromhex(state['qd'])
            return int(state['step']), list(state['grids'])
        except (OSError, KeyError, TypeError, ValueError) as e:
            raise Fail('input', f'CONFIG restart={number}: cannot read {path}: {e}') from e


def converse(sock, courant, t_wall):
    """The solver's side of the conversation after HELLO; returns the exit status."""
    compute = 0.0
    cfg = mp.recv(sock, 60000)
    if cfg.type == mp.Type.REJECT:
        print(f'modal_beam_solid: refused: {cfg.text}', file=sys.stderr)
        return 1  # no reply to a REJECT
    if cfg.type == mp.Type.ABORT:
        return 1  # the other solver failed first (PROTOCOL.md 6): the coupler says why
    if cfg.type != mp.Type.CONFIG:
        raise Fail('protocol', f'expected CONFIG or REJECT after HELLO, got {mp.Type(cfg.type).name}')
    conf = dict(line.split('=', 1) for line in cfg.text.splitlines() if line)
    for k in conf:
        if k == 'motion':
            # PROTOCOL.md 4: the tank moves; one mode of a beam clamped in a
            # fixed frame cannot follow the frame's body forces
            raise Fail('input', f"CONFIG motion={conf[k]}: the modal beam solid cannot apply a "
                                "moving tank frame (the case's motion block)")
        if k not in mp.CONFIG_KEYS:
            raise Fail('input', f"CONFIG key '{k}' unknown")
    try:
        with open(conf['case']) as f:
            config_text = f.read()
        beam = Beam(mp.Case(conf['case']), courant)
    except mp.CaseError as e:
        # PROTOCOL.md 8: one of its keys; the coupler prints the line as its own
        raise Fail('input', mp.CASE_ERROR + str(e)) from e
    except (OSError, KeyError, TypeError, ValueError, IndexError) as e:
        raise Fail('input', f"case {conf['case']}: {type(e).__name__}: {e}") from e
    timeout = int(conf.get('timeout_ms', '1800000'))
    if conf.get('rollback', 'off') not in ('on', 'off'):
        raise Fail('input', f"CONFIG rollback={conf['rollback']}: must be on or off")
    roll = mp.Rollback(conf.get('rollback') == 'on')
    step = 0
    snaps = Snapshots(conf['out'], conf['prefix'], config_text)
    ckpts = Checkpoints(conf['out'], conf['prefix'])
    number = conf.get('restart', '0')
    if not number.isdigit() or (number != '0' and int(number) < 1):
        raise Fail('input', f'CONFIG restart={number}: must be a checkpoint number >= 1')
    number = int(number)
    if number:  # the state and the snapshot series of checkpoint N
        step, snaps.grids = ckpts.read(number, beam)
        snaps.index()
    else:
        snaps.write(0, 0.0, beam)
    kept = (beam.q, beam.qd, len(snaps.grids))   # the state a repeated step starts from

    def state_msg(mtype, **kw):
        x, v = beam.state()
        return mp.Message(mtype, payload=mp.Payload.STATE, id=beam.id, x=x, v=v,
                          surface=beam.surface, fixed=beam.fixed, dt=beam.dt, **kw)

    mp.send(sock, state_msg(mp.Type.READY, text='tip_dx'))
    while True:
        m = mp.recv(sock, timeout)
        if m.type == mp.Type.STOP:
            summary = {'solver': 'modal_beam_solid', 'model': 'modal_beam', 'status': 'ok',
                       'compute_seconds': compute, 'wall_seconds': time.time() - t_wall,
                       'omega_1': beam.omega, 'f_1_hz': beam.omega / (2 * math.pi),
                       'coupling_steps': step}
            mp.send(sock, mp.Message(mp.Type.BYE, step=m.step, time=m.time, text=json.dumps(summary)))
            return 0
        if m.type == mp.Type.ABORT:
            return 1  # no reply to ABORT; the coupler tells the user why
        if m.type != mp.Type.ADVANCE:
            raise Fail('protocol', f'expected ADVANCE, STOP or ABORT, got {mp.Type(m.type).name}')
        c0 = time.time()
        # iteration 0 starts a step (kept), a later one repeats it from there; the
        # coupler's solid prediction (PROTOCOL.md 6) is such an iteration 0 under
        # the last step's loads, so nothing here needs to know about it
        if roll.check(m) == 'new':
            kept = (beam.q, beam.qd, len(snaps.grids))
        else:
            beam.q, beam.qd, n_snaps = kept
            del snaps.grids[n_snaps:]  # its snapshot is written again under the same name
            step -= 1  # counts steps, not repeats
        beam.force = 0.0
        if m.payload == mp.Payload.LOADS and m.count:
            idx = m.id.astype(np.int64)
            if idx.max() >= beam.n:
                raise Fail('input', f'LOADS id {int(idx.max())}: unknown (ids 0..{beam.n - 1})')
            if len(np.unique(idx)) != len(idx):
                raise Fail('input', 'LOADS lists an id twice')
            beam.force = float(np.sum(m.force[:, 0] * beam.phi[idx]))
        beam.advance(m.dt / m.n_sub, m.n_sub)
        step += 1
        if m.flags & mp.F_SNAPSHOT:
            snaps.write(m.step + 1, m.time + m.dt, beam)
        if m.flags & mp.F_CHECKPOINT:
            number += m.iteration == 0  # a repeated iteration rewrites the step's
            ckpts.write(number, m.time + m.dt, beam, step, snaps.grids)
        kw = {}
        if m.flags & mp.F_PROBES:
            kw = dict(flags=mp.F_PROBES, probes=np.array([beam.q]))
        res = state_msg(mp.Type.RESULT, step=m.step, iteration=m.iteration, time=m.time + m.dt, **kw)
        compute += time.time() - c0
        mp.send(sock, res)


def main():
    args = sys.argv[1:]
    endpoint = args[args.index('--connect') + 1]
    courant = float(args[args.index('--courant') + 1]) if '--courant' in args else 0.5
    key = args[args.index('--key') + 1] if '--key' in args else None
    ctx = zmq.Context()
    try:
        sock = mp.connect(ctx, endpoint, key)  # tcp: CURVE (PROTOCOL.md section 10)
    except (mp.ProtocolError, OSError, ValueError) as e:
        print(f'modal_beam_solid: input: {e}', file=sys.stderr)
        ctx.term()
        return 2
    mp.send(sock, mp.Message(mp.Type.HELLO,
                             text=f'role=solid model=modal_beam pid={os.getpid()} '
                                  'caps=rollback,checkpoint'))
    try:
        code = converse(sock, courant, time.time())
    except (Fail, mp.ProtocolError, TimeoutError) as e:
        # PROTOCOL.md 7-8: tell the coupler why (best effort), exit 2 for input, else 1
        text = str(e) if isinstance(e, Fail) else \
            f"{'protocol' if isinstance(e, mp.ProtocolError) else 'timeout'}: {e}"
        status = text.split(':', 1)[0]
        if not mp.case_error(text):  # a case error is the coupler's to print (PROTOCOL.md 8)
            print(f'modal_beam_solid: {text}', file=sys.stderr)
        try:
            mp.send(sock, mp.Message(mp.Type.ERROR, text=text))
        except (zmq.ZMQError, mp.ProtocolError):
            pass
        code = 2 if status == 'input' else 1
    sock.close()  # linger 1 s: a last BYE or ERROR still goes out
    ctx.term()
    return code


if __name__ == '__main__':
    sys.exit(main())
