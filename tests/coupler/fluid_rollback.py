#!/usr/bin/python3
"""Rollback of the fluid solver (implicit coupling, PROTOCOL.md 6), played
from the coupler's side against two fluid processes in step.

Process A repeats every step: iteration 0 with the solid at state S_k,
iteration 1 with a perturbed state (the plate 0.3 dp further and faster),
iteration 2 with S_k again. Process B takes each step once with S_k. The
checks: iteration 2 gives iteration 0's RESULT bit for bit (the state of the
step's start was restored: particles, Verlet list, PPE warm start, counters,
the time means of the sensors, asked for every third step);
iteration 1 differs (the perturbation reached the loads, so the check is not
vacuous); A's accepted RESULTs equal B's at every step, and both write the
same snapshots (a repeated step's snapshot replaces the first one's), the
last ones equal field by field. The scene is water against a plate
(tests/coupler/plate_in_water.yml) moving on a prescribed path, 60 steps, so
the Verlet list is rebuilt and the first step (which removes the walls under
the solid) is repeated too.

usage: fluid_rollback.py BUILD_BIN_DIR
"""
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np
import zmq

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', '..', 'proto', 'python'))
import mpsproto as mp  # noqa: E402

BIN = os.path.abspath(sys.argv[1])
CASE = os.path.join(HERE, 'plate_in_water.yml')
STEPS = 60
failures = []


def check(cond, what):
    print(('ok    ' if cond else 'FAIL  ') + what)
    if not cond:
        failures.append(what)


def plate(dp=0.01, x0=0.2, x1=0.24, y1=0.3):
    """The plate body of plate_in_water.yml as the solid would send it: every
    particle, the outer ones surface (not the bottom row, on the floor), the
    bottom two rows fixed."""
    nx, ny = int(round((x1 - x0) / dp)), int(round(y1 / dp))
    i, j = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny)))
    x = np.column_stack([x0 + (i + 0.5) * dp, (j + 0.5) * dp])
    surface = ((j > 0) & ((i == 0) | (i == nx - 1) | (j == ny - 1))).astype(np.uint8)
    fixed = (j < 2).astype(np.uint8)
    return np.arange(len(x), dtype=np.int32), x, surface, fixed


def state(t, push=0.0):
    """The plate bending into the water on a prescribed path (tip 2 cm at
    2 Hz); push adds a displacement (m) and a velocity (m/s) along x."""
    ids, x0, surface, fixed = plate()
    h = np.clip((x0[:, 1] - 0.02) / 0.28, 0.0, None) ** 2
    w = 2 * np.pi * 2.0
    x = x0.copy()
    v = np.zeros_like(x0)
    x[:, 0] += (-0.02 * np.sin(w * t) - push) * h
    v[:, 0] = (-0.02 * w * np.cos(w * t) - 10 * push) * h
    return mp.Message(mp.Type.ADVANCE, payload=mp.Payload.STATE, id=ids, x=x, v=v,
                      surface=surface, fixed=fixed)


class Fluid:
    def __init__(self, ctx, tmp, name):
        self.out = os.path.join(tmp, name)
        os.makedirs(self.out)
        self.sock = ctx.socket(zmq.DEALER)
        self.sock.setsockopt(zmq.LINGER, 1000)
        ep = f'ipc://{tmp}/{name}.sock'
        self.sock.bind(ep)
        self.log = open(os.path.join(tmp, name + '.log'), 'wb')
        self.proc = subprocess.Popen([os.path.join(BIN, 'fluid_solver'), '--connect', ep],
                                     stdout=self.log, stderr=subprocess.STDOUT)
        hello = self.recv()
        check('rollback' in mp.capabilities(hello.text), f'{name}: HELLO {hello.text!r}')
        mp.send(self.sock, mp.Message(mp.Type.CONFIG, text=f'case={CASE}\nout={self.out}\n'
                                      f'prefix=fluid\ntimeout_ms=60000\nrollback=on\n'))
        ready = self.recv()
        if ready.type != mp.Type.READY:
            sys.exit(f'{name}: {mp.Type(ready.type).name}: {ready.text}')
        self.dt = ready.dt

    def recv(self):
        if not self.sock.poll(60000):
            sys.exit('no answer from the fluid within 60 s')
        return mp.decode(self.sock.recv_multipart())

    def advance(self, k, it, t, dt, st, flags):
        m = mp.Message(mp.Type.ADVANCE, payload=mp.Payload.STATE, flags=flags, step=k, iteration=it,
                       time=t, dt=dt, n_sub=1, id=st.id, x=st.x, v=st.v, surface=st.surface,
                       fixed=st.fixed)
        mp.send(self.sock, m)
        frames = self.sock.recv_multipart() if self.sock.poll(60000) else None
        if frames is None:
            sys.exit(f'no RESULT for step {k} iteration {it}')
        r = mp.decode(frames)
        if r.type != mp.Type.RESULT:
            sys.exit(f'step {k} iteration {it}: {mp.Type(r.type).name}: {r.text}')
        return frames

    def stop(self, k, t):
        mp.send(self.sock, mp.Message(mp.Type.STOP, step=k, time=t))
        bye = self.recv()
        self.proc.wait(timeout=30)
        self.sock.close()
        return bye


def differs(f1, f2):
    """Which parts of two RESULTs differ (array frames and header time/dt)."""
    a, b = mp.decode(f1), mp.decode(f2)
    d = [n for n in ('time', 'dt') if getattr(a, n) != getattr(b, n)]
    return d + [f'frame {k}' for k in range(1, len(f1)) if bytes(f1[k]) != bytes(f2[k])]


def main():
    tmp = tempfile.mkdtemp(prefix='frb_')
    ctx = zmq.Context()
    try:
        a, b = Fluid(ctx, tmp, 'a'), Fluid(ctx, tmp, 'b')
        t, dt = 0.0, min(a.dt, 2e-3)
        repeat_bad, perturb_same, accepted_bad = [], 0, []
        for k in range(STEPS):
            # PROBES every third step: the time-mean probes (left_wall_force)
            # then span repeated steps, whose means a repeat must restore
            flags = (mp.F_PROBES if k % 3 == 2 else 0) | (mp.F_SNAPSHOT if k % 20 == 19 else 0)
            s, p = state(t + dt), state(t + dt, push=0.003)
            r0 = a.advance(k, 0, t, dt, s, flags)
            r1 = a.advance(k, 1, t, dt, p, flags)
            r2 = a.advance(k, 2, t, dt, s, flags)
            rb = b.advance(k, 0, t, dt, s, flags)
            if differs(r0, r2):
                repeat_bad.append((k, differs(r0, r2)))
            perturb_same += not differs(r0, r1)
            if differs(r2, rb):
                accepted_bad.append((k, differs(r2, rb)))
            t = t + dt
            dt = min(mp.decode(rb).dt, 2e-3)
        check(not repeat_bad, 'iteration 2 (state S after a perturbed iteration 1) repeats '
              f'iteration 0 bit for bit in all {STEPS} steps' + (f': {repeat_bad[:3]}' if repeat_bad else ''))
        check(perturb_same == 0, f'the perturbed iteration changed the loads in every step '
              f'({perturb_same} steps where it did not)')
        check(not accepted_bad, 'the repeated run equals the run without repeats at every step'
              + (f': {accepted_bad[:3]}' if accepted_bad else ''))
        ba, bb = a.stop(STEPS, t), b.stop(STEPS, t)
        fa = sorted(os.path.basename(f) for f in glob.glob(os.path.join(a.out, 'fluid_*.h5')))
        fb = sorted(os.path.basename(f) for f in glob.glob(os.path.join(b.out, 'fluid_*.h5')))
        check(fa == fb and len(fa) == 1 + STEPS // 20,
              f'the same snapshots written ({len(fa)}: {fa[-2:]}; without repeats {len(fb)})')
        same = True
        for name in fa:
            with h5py.File(os.path.join(a.out, name)) as ha, h5py.File(os.path.join(b.out, name)) as hb:
                for field in hb['particles']:
                    same &= np.array_equal(ha['particles'][field][()], hb['particles'][field][()])
        check(same, 'every snapshot equal field by field to the one without repeats')
        xa = open(os.path.join(a.out, 'fluid.xmf')).read()
        xb = open(os.path.join(b.out, 'fluid.xmf')).read()
        check(xa == xb, 'the XDMF index lists each snapshot once')
        sa = json.loads(ba.text)
        check(sa.get('repeated_advances') == 2 * STEPS and sa.get('advances') == 3 * STEPS,
              f'the summary counts the repeats ({sa.get("advances")} advances, '
              f'{sa.get("repeated_advances")} repeated)')
    finally:
        ctx.destroy(linger=0)
        shutil.rmtree(tmp, ignore_errors=True)
    print(f'fluid_rollback: {len(failures)} failed')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
