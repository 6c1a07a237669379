#!/usr/bin/python3
"""A toy solid for the conformance suite (conformance.py): the first body of
the case as free particles (no bonds: each particle obeys m x'' = f, clamped
ones stay put), speaking PROTOCOL.md through mpsproto. As it is, it passes the
suite, which shows the suite asks nothing beyond the protocol. By default it
cannot repeat a step (no caps=rollback); --rollback makes it declare the
capability and keep its state for implicit coupling. Each --bug breaks one
rule, so ctest can check that the suite catches it:
  --bug step       RESULT echoes step + 1
  --bug abort      ignores ABORT and waits for the next message
  --bug silent     dies on a malformed message without sending ERROR
  --bug role       says role=fluid in its HELLO
  --bug motion     accepts CONFIG motion=KIND (a moving tank) and ignores it
  --bug repeat     takes an ADVANCE of iteration > 0 as a new step, unasked
  --bug norestore  (with --rollback) repeats a step from where the last one ended
  --bug casekey    answers a bad value of one of its keys (solid.bodies.0.rho) with a
                   plain ERROR "input: ..." that names neither the key nor where it is

usage: conformance_toy_solid.py [--rollback] [--bug NAME] --connect ENDPOINT
"""
import json, os, sys

import numpy as np
import yaml
import zmq

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'proto',
                                'python'))
import mpsproto as mp  # noqa: E402

args = sys.argv[1:]
BUG = args[args.index('--bug') + 1] if '--bug' in args else None
ROLLBACK = '--rollback' in args


class Fail(Exception):
    """ERROR text "STATUS: message" (PROTOCOL.md 8)."""


def particles(case):
    """Lattice of the first body; clamped where a clamp box covers it."""
    dp, b = float(case['dp']), case['solid']['bodies'][0]
    nx = int((float(b['x1']) - float(b['x0'])) / dp + 1e-6)
    ny = int((float(b['y1']) - float(b['y0'])) / dp + 1e-6)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny)))
    x = np.column_stack([float(b['x0']) + (i + 0.5) * dp, float(b['y0']) + (j + 0.5) * dp])
    fixed = np.zeros(len(x), np.uint8)
    for c in case['solid'].get('clamps', []):
        fixed |= ((x[:, 0] > c['x0']) & (x[:, 0] < c['x1']) &
                  (x[:, 1] > c['y0']) & (x[:, 1] < c['y1'])).astype(np.uint8)
    surface = ((i == 0) | (i == nx - 1) | (j == 0) | (j == ny - 1)).astype(np.uint8)
    return x, fixed, surface, float(b.get('rho', 1000.0)) * dp * dp


def converse(sock):
    cfg = mp.recv(sock, 60000)
    if cfg.type == mp.Type.REJECT:
        return 1
    if cfg.type == mp.Type.ABORT:
        return 1
    if cfg.type != mp.Type.CONFIG:
        raise Fail(f'protocol: expected CONFIG, got {mp.Type(cfg.type).name}')
    conf = dict(line.split('=', 1) for line in cfg.text.splitlines() if line)
    # it has no body forces: a moving tank (CONFIG motion) is unknown to it
    unknown = set(conf) - {'case', 'out', 'prefix', 'timeout_ms'} - \
        ({'rollback'} if ROLLBACK else set()) - ({'motion'} if BUG == 'motion' else set())
    if unknown:
        raise Fail(f"input: CONFIG key '{sorted(unknown)[0]}' unknown")
    # its one key of its own: the first body's density (PROTOCOL.md 8, case error)
    try:
        mp.Case(conf['case']).number('solid.bodies.0.rho', 1000.0, lo=0.0, lo_open=True)
    except mp.CaseError as e:
        raise Fail('input: ' + ('bad case' if BUG == 'casekey' else mp.CASE_ERROR + str(e)))
    with open(conf['case']) as f:
        x, fixed, surface, mass = particles(yaml.safe_load(f))
    n, v, force = len(x), np.zeros_like(x), np.zeros_like(x)
    ids, dt_stable = np.arange(len(x), dtype=np.int32), 4e-4

    def snapshot(step):
        np.savetxt(os.path.join(conf['out'], f"{conf['prefix']}_{step:06d}.csv"),
                   np.column_stack([ids, x, v]), delimiter=',')

    def state(mtype, **kw):
        return mp.Message(mtype, payload=mp.Payload.STATE, id=ids, x=x, v=v, surface=surface,
                          fixed=fixed, dt=dt_stable, **kw)

    roll = mp.Rollback(conf.get('rollback') == 'on')
    kept = (x.copy(), v.copy())
    snapshot(0)
    mp.send(sock, state(mp.Type.READY))
    timeout = int(conf.get('timeout_ms', 1800000))
    while True:
        m = mp.recv(sock, timeout)
        if m.type == mp.Type.ABORT and BUG != 'abort':
            return 1
        if m.type == mp.Type.ABORT:
            continue
        if m.type == mp.Type.STOP:
            mp.send(sock, mp.Message(mp.Type.BYE, step=m.step, time=m.time,
                                     text=json.dumps({'solver': 'toy'})))
            return 0
        if m.type != mp.Type.ADVANCE:
            raise Fail(f'protocol: expected ADVANCE, STOP or ABORT, got {mp.Type(m.type).name}')
        if BUG == 'repeat' and m.iteration > 0:
            pass  # the bug: a repeat taken as a new step
        elif roll.check(m) == 'new':
            kept = (x.copy(), v.copy())
        elif BUG != 'norestore':
            x[:], v[:] = kept
        force[:] = 0.0
        if m.payload == mp.Payload.LOADS and m.count:
            if m.id.max() >= n or len(np.unique(m.id)) != m.count:
                raise Fail('protocol: LOADS with an unknown or repeated id')
            force[m.id] = m.force
        h = m.dt / m.n_sub
        for _ in range(m.n_sub):  # symplectic Euler; clamped particles never move
            v[:] = np.where(fixed[:, None] == 1, 0.0, v + h * force / mass)
            x[:] = x + h * v
        if m.flags & mp.F_SNAPSHOT:
            snapshot(m.step + 1)
        kw = dict(flags=mp.F_PROBES, probes=np.zeros(0)) if m.flags & mp.F_PROBES else {}
        mp.send(sock, state(mp.Type.RESULT, step=m.step + (BUG == 'step'),
                            iteration=m.iteration, time=m.time + m.dt, **kw))


def main():
    ctx = zmq.Context()
    sock = mp.connect(ctx, args[args.index('--connect') + 1])
    role = 'fluid' if BUG == 'role' else 'solid'
    caps = ' caps=rollback' if ROLLBACK else ''
    mp.send(sock, mp.Message(mp.Type.HELLO, text=f'role={role} model=toy pid={os.getpid()}{caps}'))
    try:
        code = converse(sock)
    except (Fail, mp.ProtocolError, TimeoutError) as e:
        if BUG == 'silent':
            os._exit(1)
        text = str(e) if isinstance(e, Fail) else \
            f"{'protocol' if isinstance(e, mp.ProtocolError) else 'timeout'}: {e}"
        mp.send(sock, mp.Message(mp.Type.ERROR, text=text))
        code = 2 if text.startswith('input:') else 1
    sock.close()
    ctx.term()
    return code


if __name__ == '__main__':
    sys.exit(main())
