#!/usr/bin/python3
"""Protocol conformance suite for solid solvers (proto/PROTOCOL.md, version 2).

Plays the coupler's side of the protocol against any solid solver command and
checks that the solid does what PROTOCOL.md says, one named check at a time
(PASS/FAIL with the reason, on stdout). Each scenario is a fresh solver
process on its own ipc endpoint in a private temporary directory, launched as
the coupler launches solvers (`COMMAND --connect ENDPOINT`, coupler/launch.c):

  run             HELLO, CONFIG/READY, six ADVANCEs (LOADS empty, NONE, zero
                  forces, then +x forces; n_sub 1 and more; PROBES and
                  SNAPSHOT flags), STOP/BYE and exit 0
  abort           ABORT after a step: no reply, exit 1 promptly (section 8)
  reject          REJECT instead of CONFIG: no reply, exit non-zero (section 6)
  bad_magic       a message with magic "XXXX" instead of CONFIG      \\
  truncated       a 40-byte header instead of an ADVANCE               > ERROR
  wrong_version   an ADVANCE of version 1                              > "protocol: ..."
  unexpected      a second CONFIG where an ADVANCE is due             /  and exit 1
  unknown_id      LOADS naming an id the solid never sent      \  ERROR (any status: the
  duplicate_id    LOADS naming one id twice                    /  spec names none), exit
                                                                  status to match (section 8)
  unknown_key     CONFIG with a key the solver cannot know: ERROR "input: ...", exit 2
  case_key        a case whose first body has rho = -2500, a key the solid owns (section 4:
                  the coupler leaves the solid's keys to it): a case error, ERROR
                  "input: case: CASE:LINE: solid.bodies.0.rho = -2500: problem" naming the
                  case file and the line where the value is, then exit 2 (section 8)
  motion          CONFIG motion=constant, the case's tank held tilted by 30 degrees with
                  gravity on: the solid refuses (ERROR "input: ...", exit 2) or applies the
                  tilted gravity (its free plate falls towards -x, section 4)
  timeout         CONFIG timeout_ms=1000, then silence: ERROR "timeout: ...", exit 1
  iteration_unasked  an ADVANCE repeating step 0 (iteration 1) without rollback=on in
                  CONFIG: ERROR "protocol: ...", exit 1
  rollback        only for a solid that declares caps=rollback in HELLO: CONFIG with
                  rollback=on, then step 0 with loads A, repeated with loads B, repeated
                  with loads A (must give iteration 0's RESULT bit for bit: the state of the
                  step's start was restored), step 1 with A twice (the same), step 2 as
                  the coupler's solid prediction runs it (iteration 0 with the last
                  step's loads A, then B twice, with SNAPSHOT and PROBES: the two B
                  iterations bit for bit), then an iteration out of order: ERROR
                  "protocol: ...", exit 1
  checkpoint      only for a solid that declares caps=checkpoint: step 0 (loads A), step 1
                  (loads A, CHECKPOINT), step 2 (loads B, PROBES), STOP; then a second
                  process with CONFIG restart=1 in the same out directory: its READY must
                  be step 1's RESULT state bit for bit and its step 2 with loads B step 2's
                  RESULT bit for bit (section 6, "Checkpoints"); a third with restart=9
                  (never written): ERROR "input: ...", exit 2; a fourth with restart=1
                  after one digit of OUT/checkpoint/*_000001.ckpt was changed (where
                  our solvers keep it; not checked if there is none): ERROR "input:
                  ...", exit 2
  checkpoint_iterations  only for a solid that declares caps=rollback,checkpoint: CONFIG
                  rollback=on, step 0 (loads A), step 1 with CHECKPOINT twice (iteration 0
                  loads B, iteration 1 loads A), step 2 (loads B, PROBES), STOP; a second
                  process with rollback=on, restart=1: READY must be iteration 1's state bit
                  for bit (each iteration rewrites checkpoint N) and its step 2 the first
                  run's step 2 (section 6, "Checkpoints")
  curve           on tcp with CURVE (section 10): the key file reaches the solver
                  as the coupler passes it (MPS_COUPLING_KEY); HELLO, READY, one
                  ADVANCE, STOP/BYE, exit 0, authenticated with the issued key
  curve_no_key    a tcp endpoint and no key: no message, exit non-zero

The case given with --case is copied with gravity set to zero (the common keys
gravity.x/y) and any --set overrides applied; its path goes to the solver in
CONFIG, as the coupler's case_resolved.yml does (the motion scenario's copy
keeps gravity and holds the tank tilted). Physical checks use only what
any elastic solid must do: unloaded and at rest it stays put, pushed +x it
moves +x, and particles flagged `fixed` never move (section 5).

Every receive has a deadline and the whole suite has one (--timeout): a hung
solver is killed (its process group) and reported, never waited for.
Exit status 0 only if every check passes. On failure one line goes to stderr
(so tests/expect_fail.sh can match it) naming the failed checks.

usage: conformance.py --solid "COMMAND [ARG]..." [--case CASE.yml]
                      [--set key=value]... [--build DIR] [--xfail CHECK]...
--build DIR: a bare program name (no '/') is looked up in DIR/bin first, as the
coupler looks beside itself (default: build/ of this repository, where
./setup.sh builds), then on PATH. --xfail CHECK (fnmatch pattern): a known failure,
printed XFAIL; if it passes it is reported XPASS and counts as a failure, so
the mark is removed once the solver is fixed.
"""
import argparse
import fnmatch
import glob
import json
import math
import os
import shlex
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np
import yaml
import zmq
from zmq.utils import z85

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, 'proto', 'python'))
import mpsproto as mp  # noqa: E402

# PROTOCOL.md section 3, written out here rather than taken from mpsproto so
# that the suite checks the bytes against the spec, not against the codec.
HEADER = struct.Struct('<4sHHIHHqiiddQII16x')
STATE_FRAMES = (('id', 4, 1), ('x', 8, 2), ('v', 8, 2), ('surface', 1, 1), ('fixed', 1, 1))
NARRAYS = {0: 0, 1: 5, 2: 3}
STATUS = ('input', 'io', 'memory', 'library', 'solver', 'diverged', 'protocol', 'timeout',
          'peer', 'interrupted')
# the motion scenario: the tank held tilted by 30 degrees counterclockwise (a
# constant tilt: no frame acceleration, the pivot does not matter), lab gravity on
MOTION_G, MOTION_ANGLE = 9.81, 30.0
MOTION_SETS = ['motion.kind=constant', f'motion.angle={MOTION_ANGLE}', 'motion.pivot.x=0.0',
               'motion.pivot.y=0.0']
EXIT_DEADLINE = 5.0     # s: a solver that has answered ERROR/BYE or got ABORT must be gone
# A key every solid owns (the first body's density) with a value none accepts: scenario case_key
BAD_KEY, BAD_VALUE = 'solid.bodies.0.rho', -2500
ABORT_DEADLINE = 3.0    # s: "well within the coupler's grace time" (5 s)


class Stop(Exception):
    """Ends a scenario early (the failed check has been reported)."""


# ---------------------------------------------------------------- reporting

class Report:
    def __init__(self, xfail):
        self.xfail = xfail
        self.results = []   # (name, verdict)

    def check(self, name, ok, reason):
        known = any(fnmatch.fnmatchcase(name, p) for p in self.xfail)
        verdict = ('XPASS' if known else 'PASS') if ok else ('XFAIL' if known else 'FAIL')
        self.results.append((name, verdict))
        print(f'{verdict:5s} {name}: {reason}', flush=True)
        return ok

    def failed(self):
        return [n for n, v in self.results if v in ('FAIL', 'XPASS')]


# ---------------------------------------------------------------- wire checks

def wire_problems(frames):
    """What is wrong with a received message, from the bytes (sections 2, 3, 5)."""
    h = frames[0]
    if len(h) < 8 or h[:4] != b'MPSC':
        return [f'magic {h[:4]!r}, expected b"MPSC"']
    version = struct.unpack_from('<H', h, 4)[0]
    if version != 2:
        return [f'version {version}, expected 2']
    if len(h) != HEADER.size:
        return [f'header frame {len(h)} bytes, expected 80']
    (_, _, mtype, flags, dim, payload, step, it, n_sub, t, dt, count, narrays,
     nprobes) = HEADER.unpack(h)
    bad = []
    if h[64:80] != bytes(16):
        bad.append('reserved bytes 64-79 not zero')
    if not 1 <= mtype <= 10:
        bad.append(f'type {mtype}')
    if dim != 2:
        bad.append(f'dim {dim}, expected 2')
    if flags & ~7:
        bad.append(f'unknown flag bits {flags & ~7:#x}')
    if payload not in NARRAYS:
        return bad + [f'payload {payload}']
    probe = 1 if mtype == 6 and flags & 4 else 0
    if narrays != NARRAYS[payload] + probe:
        bad.append(f'narrays {narrays}, expected {NARRAYS[payload] + probe}')
    want = 1 + narrays + (flags & 1)
    if len(frames) != want:
        return bad + [f'{len(frames)} frames, expected {want} (1 + narrays + TEXT)']
    if payload == 0 and count:
        bad.append(f'count {count} with payload NONE')
    if payload == 1:
        for k, (name, size, comps) in enumerate(STATE_FRAMES):
            if len(frames[1 + k]) != count * size * comps:
                bad.append(f'frame {1 + k} ({name}) {len(frames[1 + k])} bytes, '
                           f'expected {count * size * comps}')
    if probe and len(frames[1 + NARRAYS[payload]]) != 8 * nprobes:
        bad.append(f'probe frame {len(frames[1 + NARRAYS[payload]])} bytes, nprobes {nprobes}')
    if flags & 1:
        try:
            text = bytes(frames[-1]).decode('utf-8')
            if '\0' in text:
                bad.append('text has a NUL byte')
        except UnicodeDecodeError:
            bad.append('text is not UTF-8')
    for name, v in (('step', step), ('iteration', it), ('n_sub', n_sub)):
        if v < 0:
            bad.append(f'{name} {v} < 0')
    if not (math.isfinite(t) and math.isfinite(dt) and dt >= 0):
        bad.append(f'time {t}, dt {dt}: must be finite, dt >= 0')
    return bad


def fields(frames):
    """Header fields as a dict (the frame is known to be 80 bytes)."""
    names = ('magic', 'version', 'type', 'flags', 'dim', 'payload', 'step', 'iteration', 'n_sub',
             'time', 'dt', 'count', 'narrays', 'nprobes')
    return dict(zip(names, HEADER.unpack(frames[0])))


def name_of(t):
    return mp.Type(t).name if t in mp.Type._value2member_map_ else str(t)


def state_problems(m):
    """STATE payload: values and ids (section 5)."""
    bad = []
    if len(np.unique(m.id)) != len(m.id):
        bad.append('duplicate ids')
    if (np.asarray(m.id) < 0).any():
        bad.append('negative id')
    if not (np.isfinite(m.x).all() and np.isfinite(m.v).all()):
        bad.append('x or v not finite')
    if ((np.asarray(m.surface) > 1) | (np.asarray(m.fixed) > 1)).any():
        bad.append('surface/fixed not 0 or 1')
    return bad


# ---------------------------------------------------------------- one solver process

class ZapHandler:
    """The coupler's ZAP handler in miniature (section 10): admits on domain
    'solid' the one client key it is given, records every key offered."""

    def __init__(self, ctx):
        import threading
        self.sock = ctx.socket(zmq.REP)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.bind('inproc://zeromq.zap.01')
        self.allowed, self.seen, self.stop = None, [], False
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        while not self.stop:
            if not self.sock.poll(100):
                continue
            req = self.sock.recv_multipart()
            ok = (len(req) >= 7 and req[0] == b'1.0' and req[2] == b'solid' and
                  req[5] == b'CURVE' and self.allowed is not None and
                  req[6] == z85.decode(self.allowed))
            self.seen.append((req[5] if len(req) > 5 else b'?', ok))
            self.sock.send_multipart([b'1.0', req[1] if len(req) > 1 else b'',
                                      b'200' if ok else b'400', b'OK' if ok else b'no',
                                      b'solid' if ok else b'', b''])

    def close(self):
        self.stop = True
        self.thread.join()
        self.sock.close(0)


class Session:
    """One solver process on its own endpoint, with the coupler's socket."""

    def __init__(self, suite, name, curve=False, key=True):
        self.suite, self.name = suite, name
        self.dir = os.path.join(suite.tmp, name)
        self.out = os.path.join(self.dir, 'out')
        os.makedirs(self.out)
        self.env = {k: v for k, v in os.environ.items() if k != mp.KEY_ENV}
        self.sock = suite.ctx.socket(zmq.DEALER)
        self.sock.setsockopt(zmq.LINGER, 1000)
        self.sock.setsockopt(zmq.SNDTIMEO, 10000)
        if curve:
            # as the coupler does (section 10): keys made for this session,
            # the solver's key file 0600 in a private directory, its path in
            # the environment, the ZAP handler admitting that key only
            os.chmod(self.dir, 0o700)
            spub, ssec = zmq.curve_keypair()
            cpub, csec = zmq.curve_keypair()
            self.client_public = cpub
            suite.zap.allowed = cpub
            kf = os.path.join(self.dir, 'solid.key')
            fd = os.open(kf, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            with os.fdopen(fd, 'w') as f:
                f.write(f'server_public={spub.decode()}\nclient_public={cpub.decode()}\n'
                        f'client_secret={csec.decode()}\n')
            if key:
                self.env[mp.KEY_ENV] = kf
            self.sock.curve_server = True
            self.sock.curve_secretkey = ssec
            self.sock.zap_domain = b'solid'
            port = self.sock.bind_to_random_port('tcp://127.0.0.1')
            self.endpoint = f'tcp://127.0.0.1:{port}'
        else:
            self.endpoint = f'ipc://{self.dir}/solid.sock'
            self.sock.bind(self.endpoint)   # before the launch (section 6, step 1)
        self.log_path = os.path.join(self.dir, 'solver.log')
        self.log = open(self.log_path, 'wb')
        self.proc = None
        self.rc = None

    def start(self):
        try:
            self.proc = subprocess.Popen(self.suite.command + ['--connect', self.endpoint],
                                         env=self.env,
                                         stdin=subprocess.DEVNULL, stdout=self.log,
                                         stderr=subprocess.STDOUT, start_new_session=True,
                                         preexec_fn=_die_with_parent)
        except OSError as e:
            where = '' if '/' in self.suite.command[0] else \
                f' (not in {os.path.join(self.suite.args.build, "bin")} nor on PATH; see --build)'
            self.suite.check(f'{self.name}.launch', False,
                             f'cannot start {self.suite.command[0]}: {e}{where}')
            raise Stop from e
        self.suite.current = self
        self.t0 = time.monotonic()

    def recv(self, timeout_s):
        """(frames, elapsed s), or (None, elapsed) after the deadline or soon after
        the solver has exited (what it sent before exiting is still read)."""
        t0 = time.monotonic()
        end = t0 + timeout_s
        while True:
            left = end - time.monotonic()
            if self.sock.poll(max(0, int(min(left, 0.1) * 1000)), zmq.POLLIN):
                return self.sock.recv_multipart(), time.monotonic() - t0
            if left <= 0:
                return None, time.monotonic() - t0
            if self.proc is not None and self.proc.poll() is not None:
                end = min(end, time.monotonic() + 0.3)

    def send(self, msg):
        self.sock.send_multipart(mp.encode(msg) if isinstance(msg, mp.Message) else msg)

    def wait_exit(self, timeout_s):
        try:
            self.rc = self.proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.rc = None
        return self.rc

    def close(self):
        if self.proc and self.proc.poll() is None:
            kill_group(self.proc)
        self.sock.close(0)
        self.log.close()
        self.suite.current = None

    def log_tail(self, n=15):
        with open(self.log_path, 'rb') as f:
            lines = f.read().decode('utf-8', 'replace').splitlines()
        return lines[-n:]


def _die_with_parent():
    """Child side: SIGTERM if the suite dies (the coupler does the same)."""
    try:
        import ctypes
        ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except Exception:  # noqa: BLE001 - best effort
        pass


def kill_group(proc):
    """SIGKILL to the process group of a child we started (start_new_session)."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    try:
        proc.wait(timeout=5)
    except subprocess.TimeoutExpired:
        pass


def is_descendant(pid, ancestor):
    """True if pid is ancestor or below it (a wrapper script may exec or fork)."""
    for _ in range(32):
        if pid == ancestor:
            return True
        try:
            with open(f'/proc/{pid}/stat') as f:
                pid = int(f.read().rsplit(')', 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            return False
        if pid <= 1:
            return False
    return False


# ---------------------------------------------------------------- the suite

class Suite:
    def __init__(self, args):
        self.args = args
        self.report = Report(args.xfail)
        self.ctx = zmq.Context()
        self.zap = None   # section 10: started before the first CURVE socket binds
        self.tmp = tempfile.mkdtemp(prefix='conf_')   # short: ipc paths <= 107 bytes
        self.current = None
        self.command = resolve_command(args.solid, args.build)
        self.case = os.path.join(self.tmp, 'case_resolved.yml')
        self.case_motion = os.path.join(self.tmp, 'case_motion.yml')
        self.case_bad = os.path.join(self.tmp, 'case_bad_key.yml')
        try:
            self.dp = write_case(args.case, args.set, self.case)
            write_case(args.case, args.set + [f'gravity.y={-MOTION_G}'] + MOTION_SETS,
                       self.case_motion)
            write_case(args.case, args.set + [f'{BAD_KEY}={BAD_VALUE}'], self.case_bad)
        except (OSError, KeyError, TypeError, ValueError, yaml.YAMLError) as e:
            shutil.rmtree(self.tmp, ignore_errors=True)
            sys.exit(f'conformance: case {args.case}: {type(e).__name__}: {e}')

    def check(self, name, ok, reason):
        return self.report.check(name, ok, reason)

    # -- conversation pieces, each reporting its own checks

    def config_text(self, s, extra='', case=None):
        return (f'case={case or self.case}\nout={s.out}\nprefix=solid\ntimeout_ms=60000\n' +
                extra)

    def hello(self, s):
        """Starts the solver and reads its HELLO; returns the HELLO text."""
        s.start()
        frames, el = s.recv(self.args.hello_timeout)
        if frames is None:
            rc = s.proc.poll()
            self.check('hello.arrives', False,
                       f'exited with status {rc} without sending HELLO' if rc is not None else
                       f'no HELLO within {self.args.hello_timeout:g} s')
            raise Stop
        bad = wire_problems(frames)
        f = fields(frames) if not bad or len(frames[0]) == 80 else {}
        if s.name != 'run':   # the first scenario reports the details, the others rely on them
            if bad or f.get('type') != 1:
                self.check(f'{s.name}.hello', False, '; '.join(bad) or
                           f'{name_of(f["type"])} instead of HELLO')
                raise Stop
            return frames[-1].decode('utf-8', 'replace') if f['flags'] & 1 else ''
        self.check('hello.arrives', True, f'after {el:.2f} s')
        if f:
            zero = [k for k in ('step', 'iteration', 'n_sub', 'time', 'dt', 'count', 'narrays',
                                'nprobes', 'payload') if f[k]]
            if f['type'] != 1:
                bad.append(f'type {name_of(f["type"])}, expected HELLO')
            if f['flags'] != 1:
                bad.append(f'flags {f["flags"]}, expected TEXT only')
            if zero:
                bad.append(f'fields not zero: {", ".join(zero)}')
        self.check('hello.header', not bad,
                   '; '.join(bad) or '80 bytes, MPSC, version 2, dim 2, HELLO, TEXT, other fields zero')
        if bad:
            raise Stop
        text = frames[-1].decode('utf-8')
        toks = text.split(' ')
        kv = dict(t.split('=', 1) for t in toks if '=' in t)
        problems = []
        if any('=' not in t or not t.split('=', 1)[0] or any(c.isspace() for c in t) for t in toks):
            problems.append('tokens are not key=value separated by single spaces')
        if kv.get('role') != 'solid':
            problems.append(f'role={kv.get("role")}, expected solid')
        if not kv.get('model'):
            problems.append('model= missing or empty')
        pid = kv.get('pid', '')
        if not (pid.isascii() and pid.isdigit()):
            problems.append(f'pid={pid!r} not decimal')
        caps = kv.get('caps')
        if caps is not None and (not caps or any(not c for c in caps.split(','))):
            problems.append(f'caps={caps!r}: expected names separated by commas (section 4)')
        self.caps = mp.capabilities(text)
        self.check('hello.text', not problems, '; '.join(problems) or repr(text))
        if pid.isascii() and pid.isdigit():
            p = int(pid)
            ok = is_descendant(p, s.proc.pid)
            self.check('hello.pid', ok, f'pid {p}, launched {s.proc.pid}'
                       + ('' if p == s.proc.pid else ' (a descendant: a wrapper)' if ok else ''))

    def ready(self, s, extra=''):
        """CONFIG, then READY. Returns the decoded READY."""
        s.send(mp.Message(mp.Type.CONFIG, text=self.config_text(s, extra)))
        frames, el = s.recv(self.args.ready_timeout)
        quiet = s.name != 'run'
        if frames is None:
            self.check(f'{s.name}.ready' if quiet else 'ready.arrives', False,
                       f'no READY within {self.args.ready_timeout:g} s')
            raise Stop
        bad = wire_problems(frames)
        f = fields(frames) if not bad else {}
        if f and f['type'] != 4:
            bad.append(f'type {name_of(f["type"])}, expected READY'
                       + (f': {frames[-1].decode("utf-8", "replace")}' if f['flags'] & 1 else ''))
        if f and f['payload'] != 1:
            bad.append(f'payload {f["payload"]}, expected STATE (a solid)')
        m = None
        if not bad:
            try:
                m = mp.decode(frames)
            except mp.ProtocolError as e:
                bad.append(f'codec: {e}')
        if quiet:
            if bad:
                self.check(f'{s.name}.ready', False, '; '.join(bad))
                raise Stop
            return m
        self.check('ready.arrives', not bad, '; '.join(bad) or f'after {el:.2f} s, payload STATE')
        if bad:
            raise Stop
        self.check('ready.time', m.time == 0.0 and f['time'] == 0.0,
                   f'time {m.time!r} (the initial time, 0)')
        self.check('ready.dt', math.isfinite(m.dt) and m.dt > 0, f'dt {m.dt!r} s (own stable step)')
        sp = state_problems(m)
        if m.count == 0:
            sp.append('count 0: no interface')
        nfree = int(((m.surface == 1) & (m.fixed == 0)).sum())
        if nfree == 0:
            sp.append('no surface particle that is not fixed: nothing to load')
        self.check('ready.state', not sp, '; '.join(sp) or
                   f'count {m.count}, ids unique, arrays sized as count, {int(m.surface.sum())} '
                   f'surface ({nfree} not fixed), {int(m.fixed.sum())} fixed')
        names = m.probe_names()
        self.check('ready.probes', len(names) == f['nprobes'],
                   f'nprobes {f["nprobes"]}, names {names}')
        return m

    def advance(self, s, k, t, dt, n_sub, payload, loads=None, flags=0, iteration=0):
        """One ADVANCE; returns (frames, decoded RESULT) or raises Stop."""
        kw = {}
        if payload == mp.Payload.LOADS:
            ids, force = loads
            kw = dict(id=np.asarray(ids, dtype=np.int32), force=np.asarray(force, dtype=float),
                      pressure=np.linalg.norm(force, axis=1) / self.dp if len(ids) else
                      np.zeros(0))
        s.send(mp.Message(mp.Type.ADVANCE, payload=payload, flags=flags, step=k, time=t, dt=dt,
                          n_sub=n_sub, iteration=iteration, **kw))
        frames, el = s.recv(self.args.step_timeout)
        if frames is None:
            self.check(f'{s.name}.result.arrives', False,
                       f'no RESULT for step {k} within {self.args.step_timeout:g} s')
            raise Stop
        bad = wire_problems(frames)
        f = fields(frames) if not bad else {}
        if f and f['type'] != 6:
            bad.append(f'type {name_of(f["type"])}, expected RESULT'
                       + (f': {frames[-1].decode("utf-8", "replace")}' if f['flags'] & 1 else ''))
        if f and f['payload'] != 1:
            bad.append(f'payload {f["payload"]}, expected STATE')
        if f and f['flags'] & 3:
            bad.append(f'flags {f["flags"]}: TEXT/SNAPSHOT set on a RESULT')
        m = None
        if not bad:
            try:
                m = mp.decode(frames)
            except mp.ProtocolError as e:
                bad.append(f'codec: {e}')
        if bad:
            self.check(f'{s.name}.result.wire', False, f'step {k}: ' + '; '.join(bad))
            raise Stop
        return f, m

    def expect_error(self, s, label, status, code):
        """After a fault the solver must answer ERROR "STATUS: ...", send nothing more and
        exit with `code` (section 8)."""
        frames, el = s.recv(EXIT_DEADLINE)
        if frames is None:
            rc = s.wait_exit(0.1)
            self.check(f'{label}.error', False,
                       f'exited with status {rc} without sending ERROR' if rc is not None else
                       f'no ERROR within {EXIT_DEADLINE:g} s (still running)')
        else:
            bad = wire_problems(frames)
            f = fields(frames) if not bad else {}
            text = frames[-1].decode('utf-8', 'replace') if f and f['flags'] & 1 else ''
            if f and f['type'] != 9:
                bad.append(f'{name_of(f["type"])} instead of ERROR')
            elif f:
                if f['payload'] or f['count'] or f['narrays'] or f['n_sub'] or f['nprobes']:
                    bad.append('payload/count/narrays/n_sub/nprobes not zero')
                if not any(text.startswith(x + ': ') for x in STATUS):
                    bad.append(f'text {text[:80]!r} does not start with a status name')
                elif status and not text.startswith(status + ': '):
                    bad.append(f'status {text.split(":")[0]!r}, expected {status!r}')
                elif not status:
                    got = text.split(':')[0]
                    code = 2 if got == 'input' else 130 if got == 'interrupted' else 1
            self.check(f'{label}.error', not bad, '; '.join(bad) or repr(text[:120]))
        # after a normal reply instead of the ERROR the solver waits for us: no need to wait long
        wait = EXIT_DEADLINE if frames is None or len(frames[0]) != 80 or \
            fields(frames)['type'] == 9 else 0.5
        rc = s.wait_exit(wait)
        late, _ = s.recv(0.05)
        self.check(f'{label}.exit', rc == code and late is None,
                   (f'still running {wait:g} s later' if rc is None else
                    f'exit status {rc}, expected {code}') +
                   (f'; sent {name_of(fields(late)["type"]) if len(late[0]) == 80 else "?"} '
                    'after its ERROR' if late is not None else ''))

    # -- scenarios

    def scenario_run(self, s):
        a = self.args
        self.hello(s)
        r = self.ready(s)
        snaps = listing(s.out)
        self.check('ready.snapshot', bool(snaps),
                   f'initial snapshot: {sorted(snaps)[:4]} in out' if snaps else
                   'no file named solid* in the CONFIG out directory after READY (section 6, '
                   'startup 5: the initial snapshot)')
        x0 = dict(zip(r.id.tolist(), r.x))
        fixed0 = {i: x for i, x, fx in zip(r.id.tolist(), r.x, r.fixed) if fx}
        nprobes = len(r.probe_names())
        t, dt_solid, last = 0.0, r.dt, r
        fails = {'echo': [], 'time': [], 'dt': [], 'state': [], 'probes': [], 'ids': [],
                 'fixed': []}
        # step: (payload, loaded, flags, extra sub-steps)
        plan = [(mp.Payload.LOADS, False, mp.F_PROBES, 0),   # empty LOADS
                (mp.Payload.NONE, False, 0, 1),              # uncoupled: zero loads
                (mp.Payload.LOADS, False, mp.F_PROBES, 0),   # every surface id, zero force
                (mp.Payload.LOADS, True, 0, 1),
                (mp.Payload.LOADS, True, mp.F_PROBES, 0),
                (mp.Payload.LOADS, True, mp.F_SNAPSHOT | mp.F_PROBES, 2)]
        nsubs, snap_new = [], None
        for k, (payload, loaded, flags, extra) in enumerate(plan):
            dt = a.dt
            n_sub = max(1, math.ceil(dt / dt_solid * (1 - 1e-12))) + extra
            nsubs.append(n_sub)
            free = (last.surface == 1) & (last.fixed == 0)
            if payload == mp.Payload.LOADS and k == 0:
                loads = (np.zeros(0, np.int32), np.zeros((0, 2)))
            elif payload == mp.Payload.LOADS and not loaded:
                sel = last.surface == 1
                loads = (last.id[sel], np.zeros((int(sel.sum()), 2)))
            elif payload == mp.Payload.LOADS:
                loads = (last.id[free], np.tile([a.force, 0.0], (int(free.sum()), 1)))
            else:
                loads = None
            before = listing(s.out)
            f, m = self.advance(s, k, t, dt, n_sub, payload, loads, flags)
            if flags & mp.F_SNAPSHOT:
                now = listing(s.out)
                snap_new = sorted(n for n in now if now[n] != before.get(n))
            if f['step'] != k or f['iteration'] != 0:
                fails['echo'].append(f'step {k}: RESULT step {f["step"]} iteration {f["iteration"]}')
            if f['time'] != t + dt:
                fails['time'].append(f'step {k}: time {f["time"]!r}, ADVANCE time + dt = {t + dt!r}')
            if not (math.isfinite(f['dt']) and f['dt'] > 0):
                fails['dt'].append(f'step {k}: dt {f["dt"]!r}')
            fails['state'] += [f'step {k}: {p}' for p in state_problems(m)]
            want = bool(flags & mp.F_PROBES)
            got = bool(f['flags'] & mp.F_PROBES)
            if got != want:
                fails['probes'].append(f'step {k}: PROBES {"set" if got else "not set"} on the '
                                       f'RESULT, {"asked" if want else "not asked"}')
            elif want and f['nprobes'] != nprobes:
                fails['probes'].append(f'step {k}: {f["nprobes"]} probe values, READY named {nprobes}')
            elif not want and f['nprobes']:
                fails['probes'].append(f'step {k}: nprobes {f["nprobes"]} without PROBES')
            if set(m.id.tolist()) != set(x0):
                fails['ids'].append(f'step {k}: {m.count} ids, {len(set(m.id.tolist()) & set(x0))} '
                                    'of those in READY')
            for i, x, v in zip(m.id.tolist(), m.x, m.v):
                if i in fixed0 and (np.abs(x - fixed0[i]).max() > 1e-12 * self.dp
                                    or np.abs(v).max() > 0):
                    fails['fixed'].append(f'step {k}: fixed id {i} at {x.tolist()} v {v.tolist()}, '
                                          f'was at {fixed0[i].tolist()}')
                    break
            if k == 2:
                self.unloaded_check(x0, m)
            t, dt_solid, last = t + dt, f['dt'], m
        self.loaded_check(x0, last)
        n = len(plan)
        self.check('result.echo', not fails['echo'], '; '.join(fails['echo'][:3]) or
                   f'{n} RESULTs echo step 0..{n - 1} and iteration 0')
        self.check('result.time', not fails['time'], '; '.join(fails['time'][:3]) or
                   'every RESULT time == ADVANCE time + dt exactly (one f64 addition)')
        self.check('result.dt', not fails['dt'], '; '.join(fails['dt'][:3]) or
                   f'next stable step > 0 (last {dt_solid:.3g} s); n_sub sent {nsubs}')
        self.check('result.state', not fails['state'], '; '.join(fails['state'][:3]) or
                   'STATE ids unique, x and v finite, arrays sized as count')
        # section 5: the interface may change between steps, so this is told, not checked
        print('INFO  result.ids: ' + ('; '.join(fails['ids'][:3]) + ' (allowed: section 5)'
                                      if fails['ids'] else f'the {len(x0)} ids of READY every step'))
        self.check('result.probes', not fails['probes'], '; '.join(fails['probes'][:3]) or
                   f'probe frame of {nprobes} values iff PROBES was asked')
        self.check('physics.fixed_stay', not fails['fixed'], '; '.join(fails['fixed'][:2]) or
                   f'{len(fixed0)} fixed particles did not move (section 5: "never moves")')
        self.check('result.snapshot', bool(snap_new),
                   f'ADVANCE with SNAPSHOT wrote {snap_new[:4]}' if snap_new else
                   'ADVANCE with SNAPSHOT created or changed no solid* file in out')
        late, _ = s.recv(0.2)
        self.check('quiet.unasked', late is None,
                   'nothing sent unasked between requests' if late is None else
                   f'an unasked message pending before STOP ({len(late)} frames)')
        s.send(mp.Message(mp.Type.STOP, step=n, time=t))
        frames, el = s.recv(EXIT_DEADLINE)
        bad = ['no BYE within %g s' % EXIT_DEADLINE] if frames is None else wire_problems(frames)
        if not bad:
            f = fields(frames)
            text = frames[-1].decode('utf-8', 'replace') if f['flags'] & 1 else None
            if f['type'] != 8:
                bad.append(f'{name_of(f["type"])} instead of BYE' + (f': {text}' if text else ''))
            elif f['payload'] or f['narrays'] or f['count']:
                bad.append('BYE carries a payload')
            elif text is None:
                bad.append('BYE has no text')
            else:
                try:
                    if not isinstance(json.loads(text), dict):
                        bad.append('BYE text is JSON but not an object')
                except ValueError as e:
                    bad.append(f'BYE text is not JSON: {e}')
                if f['time'] != t:
                    bad.append(f'BYE time {f["time"]!r}, last state at {t!r}')
        self.check('stop.bye', not bad, '; '.join(bad) or
                   f'BYE with a JSON object ({len(text)} bytes), time {t:g}, step {f["step"]}')
        rc = s.wait_exit(EXIT_DEADLINE)
        self.check('stop.exit', rc == 0, f'exit status {rc}' if rc is not None else
                   f'still running {EXIT_DEADLINE:g} s after STOP')

    def unloaded_check(self, x0, m):
        common = [k for k, i in enumerate(m.id.tolist()) if i in x0]
        dx = np.array([m.x[k] - x0[m.id[k]] for k in common])
        dmax = float(np.abs(dx).max()) if len(dx) else 0.0
        vmax = float(np.abs(m.v).max()) if m.count else 0.0
        tol = self.args.rest_tol * self.dp
        self.check('physics.unloaded_at_rest', dmax <= tol and vmax <= tol / self.args.dt,
                   f'after 3 unloaded steps (empty LOADS, NONE, zero forces), no gravity: '
                   f'max |dx| {dmax:.2e} m, max |v| {vmax:.2e} m/s (tolerance {tol:.1e} m)')

    def loaded_check(self, x0, m):
        free = (m.surface == 1) & (m.fixed == 0)
        dx = np.array([m.x[k] - x0[i] for k, i in enumerate(m.id.tolist()) if free[k] and i in x0])
        mx = float(dx[:, 0].mean()) if len(dx) else float('nan')
        my = float(dx[:, 1].mean()) if len(dx) else float('nan')
        self.check('physics.load_moves_x', mx > 0,
                   f'after 3 steps with +x force {self.args.force:g} N/m on the {len(dx)} free '
                   f'surface particles: mean dx {mx:.3e} m, mean dy {my:.3e} m')

    def scenario_abort(self, s):
        self.hello(s)
        r = self.ready(s)
        self.advance(s, 0, 0.0, r.dt, 1, mp.Payload.NONE)
        s.send(mp.Message(mp.Type.ABORT, text='conformance: ABORT test'))
        t0 = time.monotonic()
        rc = s.wait_exit(ABORT_DEADLINE)
        late, _ = s.recv(0.05)
        self.check('abort.exit', rc == 1, f'exit status {rc} after {time.monotonic() - t0:.2f} s'
                   if rc is not None else f'still running {ABORT_DEADLINE:g} s after ABORT')
        self.check('abort.no_reply', late is None, 'no reply to ABORT' if late is None else
                   'replied to ABORT')

    def scenario_reject(self, s):
        self.hello(s)
        s.send(mp.Message(mp.Type.REJECT, text='conformance: refused on purpose'))
        rc = s.wait_exit(EXIT_DEADLINE)
        late, _ = s.recv(0.05)
        self.check('reject.exit', rc not in (None, 0) and late is None,
                   (f'exit status {rc}' if rc is not None else
                    f'still running {EXIT_DEADLINE:g} s after REJECT') +
                   ('' if late is None else '; replied to REJECT'))

    def scenario_bad_magic(self, s):
        self.hello(s)
        frames = mp.encode(mp.Message(mp.Type.CONFIG, text=self.config_text(s)))
        frames[0] = b'XXXX' + frames[0][4:]
        s.send(frames)
        self.expect_error(s, 'malformed.bad_magic', 'protocol', 1)

    def scenario_truncated(self, s):
        self.hello(s)
        self.ready(s)
        frames = mp.encode(mp.Message(mp.Type.ADVANCE, step=0, time=0.0, dt=1e-6, n_sub=1))
        s.send([frames[0][:40]])
        self.expect_error(s, 'malformed.truncated', 'protocol', 1)

    def scenario_wrong_version(self, s):
        self.hello(s)
        self.ready(s)
        frames = mp.encode(mp.Message(mp.Type.ADVANCE, step=0, time=0.0, dt=1e-6, n_sub=1))
        frames[0] = frames[0][:4] + struct.pack('<H', 1) + frames[0][6:]
        s.send(frames)
        self.expect_error(s, 'malformed.wrong_version', 'protocol', 1)

    def scenario_unexpected(self, s):
        self.hello(s)
        self.ready(s)
        s.send(mp.Message(mp.Type.CONFIG, text=self.config_text(s)))
        self.expect_error(s, 'unexpected_type', 'protocol', 1)

    def bad_loads(self, s, label, ids_of):
        """LOADS that a receiver must reject (section 5): any ERROR status will do
        (the spec names none), with the matching exit status."""
        self.hello(s)
        r = self.ready(s)
        ids = np.asarray(ids_of(r.id[r.surface == 1]), dtype=np.int32)
        s.send(mp.Message(mp.Type.ADVANCE, payload=mp.Payload.LOADS, step=0, time=0.0, dt=r.dt,
                          n_sub=1, id=ids, pressure=np.zeros(len(ids)),
                          force=np.zeros((len(ids), 2))))
        self.expect_error(s, label, None, 1)

    def scenario_unknown_id(self, s):
        self.bad_loads(s, 'loads.unknown_id', lambda sid: [int(sid.max()) + 1000])

    def scenario_duplicate_id(self, s):
        self.bad_loads(s, 'loads.duplicate_id', lambda sid: [sid[0], sid[0]])

    def scenario_unknown_key(self, s):
        self.hello(s)
        s.send(mp.Message(mp.Type.CONFIG,
                          text=self.config_text(s, 'conformance_no_such_key=1\n')))
        self.expect_error(s, 'config.unknown_key', 'input', 2)

    def scenario_case_key(self, s):
        """A wrong value of one of the solid's own keys (sections 4 and 8): a case error
        naming the file, the line, the key and the value."""
        self.hello(s)
        s.send(mp.Message(mp.Type.CONFIG, text=self.config_text(s, case=self.case_bad)))
        frames, _ = s.recv(self.args.ready_timeout)
        bad = ['no answer to CONFIG'] if frames is None else wire_problems(frames)
        f = fields(frames) if not bad else {}
        text = frames[-1].decode('utf-8', 'replace') if f and f['type'] == 9 and \
            f['flags'] & 1 else ''
        where = f'{self.case_bad}:{value_line(self.case_bad, BAD_KEY)}: {BAD_KEY} = {BAD_VALUE}'
        line = mp.case_error(text)
        if f and f['type'] != 9:
            bad.append(f'{name_of(f["type"])} instead of ERROR')
        elif f and line is None:
            bad.append(f'ERROR {text[:100]!r} is not a case error "input: case: ..."')
        elif f and not line.startswith(where + ': '):
            bad.append(f'the case error {line[:160]!r} does not start with {where + ": "!r}')
        self.check('case_key.error', not bad, '; '.join(bad) or repr(text[:160]))
        rc = s.wait_exit(EXIT_DEADLINE)
        late, _ = s.recv(0.05)
        self.check('case_key.exit', rc == 2 and late is None,
                   (f'still running {EXIT_DEADLINE:g} s later' if rc is None else
                    f'exit status {rc}, expected 2') + ('; sent more after its ERROR'
                                                         if late is not None else ''))

    def scenario_motion(self, s):
        """A moving tank (section 4): READY and the tilted gravity applied, or a refusal."""
        self.hello(s)
        s.send(mp.Message(mp.Type.CONFIG, text=self.config_text(s, 'motion=constant\n',
                                                                case=self.case_motion)))
        frames, _ = s.recv(self.args.ready_timeout)
        bad = ['no answer to CONFIG'] if frames is None else wire_problems(frames)
        f = fields(frames) if not bad else {}
        if f and f['type'] == 9:
            text = frames[-1].decode('utf-8', 'replace') if f['flags'] & 1 else ''
            rc = s.wait_exit(EXIT_DEADLINE)
            ok = text.startswith('input: ') and rc == 2
            self.check('motion.answer', ok, f'refused: {text[:100]!r}, exit status {rc}' +
                       ('' if ok else ' (a refusal is ERROR "input: ..." and exit 2)'))
            return
        if f and (f['type'] != 4 or f['payload'] != 1):
            bad.append(f'{name_of(f["type"])} instead of READY (STATE) or ERROR')
        r = None
        if not bad:
            try:
                r = mp.decode(frames)
            except mp.ProtocolError as e:
                bad.append(f'codec: {e}')
        self.check('motion.answer', not bad, '; '.join(bad) or 'READY: it applies the motion')
        if bad:
            raise Stop
        x0 = {int(i): r.x[k].copy() for k, i in enumerate(r.id)}
        n_sub, steps, t, last = 20, 5, 0.0, r
        for k in range(steps):  # each step from the latest stable step (it may shrink)
            dt = n_sub * last.dt
            _, last = self.advance(s, k, t, dt, n_sub, mp.Payload.NONE)
            t += dt
        free = (last.surface == 1) & (last.fixed == 0)
        dx = np.array([last.x[k] - x0[i] for k, i in enumerate(last.id.tolist())
                       if free[k] and i in x0])
        mx = float(dx[:, 0].mean()) if len(dx) else float('nan')
        # long before the plate's first period the free particles fall freely
        # along the tilted gravity's x component, -g sin(30 deg)
        fall = 0.5 * MOTION_G * math.sin(math.radians(MOTION_ANGLE)) * t * t
        self.check('motion.honoured', mx < -0.25 * fall,
                   f'after {t:.3g} s at a {MOTION_ANGLE:g} deg tilt: mean dx of the {len(dx)} free '
                   f'surface particles {mx:.3e} m (free fall along the tilt: -{fall:.3e} m; '
                   f'needs < -{0.25 * fall:.3e})')
        s.send(mp.Message(mp.Type.STOP, step=steps, time=t))
        s.recv(self.args.step_timeout)
        s.wait_exit(EXIT_DEADLINE)

    def scenario_timeout(self, s):
        self.hello(s)
        s.send(mp.Message(mp.Type.CONFIG, text=self.config_text(s).replace(
            'timeout_ms=60000', 'timeout_ms=1000')))
        frames, _ = s.recv(self.args.ready_timeout)
        if frames is None or len(frames[0]) != 80 or fields(frames)['type'] != 4:
            self.check('timeout.ready', False, 'no READY')
            raise Stop
        self.expect_error(s, 'timeout', 'timeout', 1)

    def scenario_iteration_unasked(self, s):
        """Section 6: a repeated step (iteration > 0) only after rollback=on."""
        self.hello(s)
        r = self.ready(s)
        self.advance(s, 0, 0.0, self.args.dt, self.n_sub(r.dt), mp.Payload.NONE)
        s.send(mp.Message(mp.Type.ADVANCE, step=0, iteration=1, time=0.0, dt=self.args.dt,
                          n_sub=self.n_sub(r.dt)))
        self.expect_error(s, 'iteration_unasked', 'protocol', 1)

    def n_sub(self, dt_solid):
        return max(1, math.ceil(self.args.dt / dt_solid * (1 - 1e-12)))

    def scenario_rollback(self, s):
        """Section 6, implicit coupling: a repeated step starts from the state the
        step started from, so the same loads give the same RESULT bit for bit."""
        text = self.hello(s)
        if 'rollback' not in mp.capabilities(text):
            print(f'INFO  rollback: the solid declares no caps=rollback ({text!r}): it cannot '
                  'run under coupling.scheme: implicit; not checked')
            return
        r = self.ready(s, 'rollback=on\n')
        self.check('rollback.config', True, 'READY after CONFIG rollback=on')
        free = (r.surface == 1) & (r.fixed == 0)
        ids = r.id[free]

        def loads(fx):
            return (ids, np.tile([fx, 0.0], (len(ids), 1)))

        a, b = loads(self.args.force), loads(-3.0 * self.args.force)
        dt, n = self.args.dt, self.n_sub(r.dt)
        fl = mp.F_PROBES

        def result(k, it, ld, flags=fl):
            s.send(mp.Message(mp.Type.ADVANCE, payload=mp.Payload.LOADS, flags=flags, step=k,
                              iteration=it, time=k * dt, dt=dt, n_sub=n,
                              id=np.asarray(ld[0], np.int32), force=ld[1],
                              pressure=np.zeros(len(ld[0]))))
            frames, _ = s.recv(self.args.step_timeout)
            bad = ['no RESULT'] if frames is None else wire_problems(frames)
            f = fields(frames) if not bad else {}
            if f and (f['type'] != 6 or f['step'] != k or f['iteration'] != it):
                bad.append(f'{name_of(f["type"])} step {f["step"]} iteration {f["iteration"]}'
                           + (f': {frames[-1].decode("utf-8", "replace")}' if f['flags'] & 1 else ''))
            if bad:
                self.check(f'rollback.step{k}.iteration{it}', False, '; '.join(bad))
                raise Stop
            return frames

        def same(f1, f2):
            """Bit for bit: every array frame and the header's time, dt and nprobes."""
            h1, h2 = fields(f1), fields(f2)
            keys = ('time', 'dt', 'count', 'nprobes')
            diff = [k for k in keys if h1[k] != h2[k]]
            diff += [f'frame {k}' for k in range(1, len(f1)) if bytes(f1[k]) != bytes(f2[k])]
            return diff

        # step 0 without PROBES, step 1 with: step 1's probe row holds the means
        # over both steps (time-mean load probes, solid_loadprobe.h), so a
        # solid that does not restore its means at a repeat shows in step 1
        r0 = result(0, 0, a, 0)
        r1 = result(0, 1, b, 0)
        self.check('rollback.loads_matter', bool(same(r0, r1)),
                   'loads B gave another RESULT than loads A in the same step' if same(r0, r1)
                   else 'loads A and B gave the same RESULT: the repeat checks below prove nothing')
        r2 = result(0, 2, a, 0)
        d = same(r0, r2)
        self.check('rollback.repeat', not d,
                   'step 0 repeated with loads A after B: the RESULT of iteration 0 bit for bit'
                   if not d else f'differs from iteration 0 in {", ".join(d)}: the state of the '
                   'step\'s start was not restored')
        r3 = result(1, 0, a, fl | mp.F_SNAPSHOT)
        r4 = result(1, 1, a, fl | mp.F_SNAPSHOT)
        d = same(r3, r4)
        self.check('rollback.repeat_next_step', not d,
                   'step 1 (from the accepted iteration 2 of step 0) repeated with the same loads: '
                   'bit for bit' if not d else f'differs in {", ".join(d)}')
        # the coupler's solid prediction (section 6, coupling.implicit.predictor:
        # solid): the solid alone under the last step's loads as iteration 0, then
        # the fluid's loads as iterations 1, 2, ..., every one with the step's flags
        fs = fl | mp.F_SNAPSHOT
        p0, p1, p2 = result(2, 0, a, fs), result(2, 1, b, fs), result(2, 2, b, fs)
        d = same(p1, p2)
        self.check('rollback.prediction', not d and bool(same(p0, p1)),
                   'step 2 predicted under loads A, then B twice: the two B iterations bit for '
                   'bit' if not d else f'the B iterations after the prediction differ in '
                   f'{", ".join(d)}: the prediction\'s step was not undone')
        s.send(mp.Message(mp.Type.ADVANCE, payload=mp.Payload.NONE, step=2, iteration=4,
                          time=2 * dt, dt=dt, n_sub=n))
        self.expect_error(s, 'rollback.out_of_order', 'protocol', 1)

    def scenario_checkpoint(self, s):
        """Section 6, checkpoints: a solver restarted from checkpoint N goes on
        exactly as the solver that wrote it."""
        text = self.hello(s)
        if 'checkpoint' not in mp.capabilities(text):
            print(f'INFO  checkpoint: the solid declares no caps=checkpoint ({text!r}): a run '
                  'that asks for checkpoints or restarts refuses it; not checked')
            return
        r = self.ready(s)
        free = (r.surface == 1) & (r.fixed == 0)
        ids = r.id[free]
        a = (ids, np.tile([self.args.force, 0.0], (len(ids), 1)))
        b = (ids, np.tile([-3.0 * self.args.force, 0.0], (len(ids), 1)))
        dt, n = self.args.dt, self.n_sub(r.dt)
        self.advance(s, 0, 0.0, dt, n, mp.Payload.LOADS, a)
        f1, m1 = self.advance(s, 1, dt, dt, n, mp.Payload.LOADS, a, mp.F_CHECKPOINT)
        f2, m2 = self.advance(s, 2, 2 * dt, dt, n, mp.Payload.LOADS, b, mp.F_PROBES)
        s.send(mp.Message(mp.Type.STOP, step=3, time=3 * dt))
        bye, _ = s.recv(EXIT_DEADLINE)
        rc = s.wait_exit(EXIT_DEADLINE)
        self.check('checkpoint.run', bye is not None and rc == 0,
                   f'steps 0-2 (CHECKPOINT on step 1), BYE, exit {rc}')
        s2 = Session(self, 'checkpoint_restart')
        s2.out = s.out  # where the first process wrote its checkpoint
        try:
            self.hello(s2)
            m = self.ready(s2, 'restart=1\n')
            d = [k for k in ('x', 'v', 'id', 'surface', 'fixed')
                 if getattr(m, k).tobytes() != getattr(m1, k).tobytes()]
            self.check('checkpoint.ready', not d and m.dt == m1.dt,
                       'READY after CONFIG restart=1: the state and stable step of step 1\'s '
                       'RESULT bit for bit' if not d and m.dt == m1.dt else
                       f'differs from step 1\'s RESULT in {", ".join(d) or "dt"}')
            g2, n2 = self.advance(s2, 2, 2 * dt, dt, n, mp.Payload.LOADS, b, mp.F_PROBES)
            d = [k for k in ('x', 'v', 'id', 'surface', 'fixed', 'probes')
                 if np.asarray(getattr(m2, k)).tobytes() != np.asarray(getattr(n2, k)).tobytes()]
            d += [k for k in ('time', 'dt', 'nprobes') if f2[k] != g2[k]]
            self.check('checkpoint.continue', not d,
                       'step 2 after the restart: the RESULT of the uninterrupted run bit for bit'
                       if not d else f'differs in {", ".join(d)}')
        except Stop:
            pass
        finally:
            s2.close()
        self.restart_refused(s.out, 9, 'checkpoint.missing')
        self.checkpoint_damaged(s.out)

    def restart_refused(self, out, number, name):
        """A new solver process told to restart from checkpoint `number` in out
        must answer an input error and exit 2."""
        s = Session(self, name.replace('.', '_'))
        s.out = out
        try:
            self.hello(s)
            s.send(mp.Message(mp.Type.CONFIG, text=self.config_text(s, f'restart={number}\n')))
            self.expect_error(s, name, 'input', 2)
        except Stop:
            pass
        finally:
            s.close()

    def scenario_checkpoint_iterations(self, s):
        """Section 6, checkpoints under implicit coupling: CHECKPOINT comes on every
        iteration of the step and each rewrites checkpoint N, so checkpoint N holds the
        last iteration's state, the one the next step starts from (the coupler's
        restart of an implicit run relies on it, docs/restart.md)."""
        text = self.hello(s)
        caps = mp.capabilities(text)
        if 'checkpoint' not in caps or 'rollback' not in caps:
            print(f'INFO  checkpoint_iterations: the solid lacks caps=rollback,checkpoint '
                  f'({text!r}): not checked')
            return
        r = self.ready(s, 'rollback=on\n')
        free = (r.surface == 1) & (r.fixed == 0)
        ids = r.id[free]
        a = (ids, np.tile([self.args.force, 0.0], (len(ids), 1)))
        b = (ids, np.tile([-3.0 * self.args.force, 0.0], (len(ids), 1)))
        dt, n = self.args.dt, self.n_sub(r.dt)
        L, ck = mp.Payload.LOADS, mp.F_CHECKPOINT
        self.advance(s, 0, 0.0, dt, n, L, a)
        _, m0 = self.advance(s, 1, dt, dt, n, L, b, ck, iteration=0)
        _, m1 = self.advance(s, 1, dt, dt, n, L, a, ck, iteration=1)
        f2, m2 = self.advance(s, 2, 2 * dt, dt, n, L, b, mp.F_PROBES)
        s.send(mp.Message(mp.Type.STOP, step=3, time=3 * dt))
        bye, _ = s.recv(EXIT_DEADLINE)
        rc = s.wait_exit(EXIT_DEADLINE)
        self.check('checkpoint_iterations.run', bye is not None and rc == 0 and
                   m0.x.tobytes() != m1.x.tobytes(),
                   f'steps 0-2, step 1 repeated with other loads (CHECKPOINT on both '
                   f'iterations), BYE, exit {rc}' + ('' if m0.x.tobytes() != m1.x.tobytes() else
                                                     ': the two iterations gave one state'))
        s2 = Session(self, 'checkpoint_iterations_restart')
        s2.out = s.out
        try:
            self.hello(s2)
            m = self.ready(s2, 'rollback=on\nrestart=1\n')
            d = [k for k in ('x', 'v') if getattr(m, k).tobytes() != getattr(m1, k).tobytes()]
            self.check('checkpoint_iterations.ready', not d and m.dt == m1.dt,
                       'READY after restart=1: the state of step 1\'s last iteration bit for bit'
                       if not d and m.dt == m1.dt else
                       f'differs from step 1\'s last iteration in {", ".join(d) or "dt"}' +
                       (' (it is the first iteration\'s)' if m.x.tobytes() == m0.x.tobytes()
                        else ''))
            g2, n2 = self.advance(s2, 2, 2 * dt, dt, n, L, b, mp.F_PROBES)
            d = [k for k in ('x', 'v', 'probes')
                 if np.asarray(getattr(m2, k)).tobytes() != np.asarray(getattr(n2, k)).tobytes()]
            d += [k for k in ('time', 'dt', 'nprobes') if f2[k] != g2[k]]
            self.check('checkpoint_iterations.continue', not d,
                       'step 2 after the restart: the uninterrupted RESULT bit for bit'
                       if not d else f'differs in {", ".join(d)}')
        except Stop:
            pass
        finally:
            s2.close()

    def checkpoint_damaged(self, out):
        """A checkpoint changed on disk (one digit) must be refused as an input
        error, not read as another state. Where a solver keeps its checkpoints
        is its own business (PROTOCOL.md 6): this looks for ours,
        OUT/checkpoint/*_000001.ckpt, and says so when there is none."""
        files = sorted(glob.glob(os.path.join(out, 'checkpoint', '*_000001.ckpt')))
        if not files:
            print('INFO  checkpoint.damaged: no OUT/checkpoint/*_000001.ckpt (the solver keeps '
                  'its checkpoints elsewhere): not checked')
            return
        with open(files[0], 'rb') as f:
            data = bytearray(f.read())
        # the first decimal digit from the middle on: changed, a JSON or a
        # binary file stays readable as a file of that format
        k = next((i for i in range(len(data) // 2, len(data)) if 48 <= data[i] <= 57), None)
        if k is None:
            print('INFO  checkpoint.damaged: no digit in the second half of the file: not checked')
            return
        data[k] = 49 if data[k] != 49 else 50
        with open(files[0], 'wb') as f:
            f.write(data)
        self.restart_refused(out, 1, 'checkpoint.damaged')

    def scenario_curve(self, s):
        """Section 10: a whole short conversation over tcp with CURVE."""
        self.hello(s)
        r = self.ready(s)
        self.advance(s, 0, 0.0, r.dt, 1, mp.Payload.NONE)
        s.send(mp.Message(mp.Type.STOP, step=1, time=r.dt))
        frames, _ = s.recv(EXIT_DEADLINE)
        ok = frames is not None and len(frames[0]) == 80 and fields(frames)['type'] == 8
        rc = s.wait_exit(EXIT_DEADLINE)
        self.check('curve.run', ok and rc == 0,
                   f'HELLO, READY, RESULT, BYE over CURVE, exit {rc}' if ok else
                   f'no BYE after STOP (exit {rc})')
        seen = self.zap.seen
        self.check('curve.authenticated', seen and all(k == b'CURVE' and a for k, a in seen),
                   f'{len(seen)} handshake(s), each CURVE with the key issued'
                   if seen and all(a for _, a in seen) else f'ZAP saw {seen}')

    def scenario_curve_no_key(self, s):
        """Section 10: no key, no connection: the solver must give up, not
        fall back to an unauthenticated link."""
        s.start()
        frames, _ = s.recv(EXIT_DEADLINE)
        rc = s.wait_exit(EXIT_DEADLINE)
        self.check('curve.no_key', frames is None and rc not in (None, 0),
                   (f'exit status {rc}' if rc is not None else
                    f'still running {EXIT_DEADLINE:g} s later') +
                   ('' if frames is None else '; a message got through'))

    SCENARIOS = ('run', 'abort', 'reject', 'bad_magic', 'truncated', 'wrong_version',
                 'unexpected', 'unknown_id', 'duplicate_id', 'unknown_key', 'case_key', 'motion',
                 'timeout', 'iteration_unasked', 'rollback', 'checkpoint', 'checkpoint_iterations',
                 'curve', 'curve_no_key')

    def run(self):
        print(f'conformance: solid {" ".join(self.command)}, case {self.args.case}', flush=True)
        for name in self.SCENARIOS:
            if name.startswith('curve') and self.zap is None:
                self.zap = ZapHandler(self.ctx)
            if name.startswith('curve'):
                self.zap.seen = []
            s = Session(self, name, curve=name.startswith('curve'), key=name == 'curve')
            n0 = len(self.report.failed())
            try:
                getattr(self, 'scenario_' + name)(s)
            except Stop:
                pass
            finally:
                s.close()
            if len(self.report.failed()) > n0:
                tail = s.log_tail()
                print(f'      solver output ({name}), last lines:' if tail else
                      f'      solver output ({name}): none')
                for line in tail:
                    print('      | ' + line)
            if name == 'run' and set(self.report.failed()) & {'run.launch', 'hello.arrives'}:
                print('      the solver cannot be reached: the other scenarios are skipped')
                break
        if self.zap is not None:
            self.zap.close()
        self.ctx.term()


def listing(d):
    """Files in d named solid* (the CONFIG prefix), with size and mtime."""
    out = {}
    for n in os.listdir(d):
        if n.startswith('solid'):
            st = os.stat(os.path.join(d, n))
            out[n] = (st.st_size, st.st_mtime_ns)
    return out


def resolve_command(command, build):
    words = shlex.split(command)
    if not words:
        sys.exit('conformance: --solid is empty')
    if '/' not in words[0] and build:
        cand = os.path.join(build, 'bin', words[0])
        if os.access(cand, os.X_OK):
            words[0] = cand
    elif '/' in words[0]:
        words[0] = os.path.abspath(words[0])
    return words


def value_line(path, key):
    """The line (1-based) of key's value in the YAML file path."""
    node = yaml.compose(open(path))
    for part in key.split('.'):
        if isinstance(node, yaml.SequenceNode):
            node = node.value[int(part)]
        else:
            node = next(v for k, v in node.value if k.value == part)
    return node.start_mark.line + 1


def write_case(path, sets, dest):
    """The case as the coupler hands it over: overrides applied, here gravity 0."""
    with open(path) as f:
        case = yaml.safe_load(f)
    case['gravity'] = {'x': 0.0, 'y': 0.0}
    for kv in sets:
        key, _, value = kv.partition('=')
        node, parts = case, key.split('.')
        for p in parts[:-1]:
            node = node[int(p)] if isinstance(node, list) else node.setdefault(p, {})
        node[int(parts[-1]) if isinstance(node, list) else parts[-1]] = yaml.safe_load(value)
    with open(dest, 'w') as f:
        yaml.safe_dump(case, f, sort_keys=False)
    return float(case['dp'])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--solid', required=True, help='solid solver command (quoted)')
    ap.add_argument('--case', default=os.path.join(HERE, 'conformance_case.yml'))
    ap.add_argument('--set', action='append', default=[], metavar='KEY=VALUE')
    ap.add_argument('--build', default=os.path.join(HERE, '..', '..', 'build'),
                    help='build directory: bare program names are looked up in BUILD/bin '
                         '(default: build/ of this repository)')
    ap.add_argument('--xfail', action='append', default=[], metavar='CHECK',
                    help='a check known to fail (fnmatch pattern)')
    ap.add_argument('--dt', type=float, default=1e-3, help='coupling step, s (default 1e-3)')
    ap.add_argument('--force', type=float, default=1.0,
                    help='+x force per free surface particle in the loaded steps, N/m (default 1)')
    ap.add_argument('--rest-tol', type=float, default=1e-9,
                    help='unloaded motion allowed, in dp (default 1e-9)')
    ap.add_argument('--hello-timeout', type=float, default=10.0)
    ap.add_argument('--ready-timeout', type=float, default=30.0)
    ap.add_argument('--step-timeout', type=float, default=30.0)
    ap.add_argument('--timeout', type=float, default=120.0, help='whole suite, s')
    ap.add_argument('--keep', action='store_true', help='keep the temporary directory')
    args = ap.parse_args()
    os.environ.setdefault('OMP_NUM_THREADS', '1')
    os.environ.setdefault('OMP_WAIT_POLICY', 'passive')
    suite = Suite(args)

    def overall(signum, frame):
        print(f'FAIL  suite.timeout: the suite did not finish within {args.timeout:g} s', flush=True)
        if suite.current and suite.current.proc:
            kill_group(suite.current.proc)
        if not args.keep:
            shutil.rmtree(suite.tmp, ignore_errors=True)
        print(f'conformance: the suite did not finish within {args.timeout:g} s '
              f'(solid: {args.solid})', file=sys.stderr)
        os._exit(1)

    signal.signal(signal.SIGALRM, overall)
    signal.alarm(max(1, int(args.timeout)))
    try:
        suite.run()
    finally:
        signal.alarm(0)
        if not args.keep:
            shutil.rmtree(suite.tmp, ignore_errors=True)
    failed = suite.report.failed()
    n = len(suite.report.results)
    xf = sum(1 for _, v in suite.report.results if v == 'XFAIL')
    print(f'conformance: {n - len(failed) - xf} passed, {len(failed)} failed'
          + (f', {xf} known failures (--xfail)' if xf else ''))
    if failed:
        print(f'conformance: {len(failed)} of {n} checks failed for solid \'{args.solid}\': '
              + ', '.join(failed), file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
