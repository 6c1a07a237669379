#!/usr/bin/python3
"""Proof that a restarted run is the uninterrupted run, bit for bit (docs/restart.md).

  restart_check.py OUT HALF STOP PROGRAM CASE [ARGS...] [--require COLUMN]

runs PROGRAM CASE ARGS --out OUT/full (the reference), then the same with
--out OUT/cut --stop-at STOP (it stops at its first checkpoint at or after
STOP, as if killed there; ARGS set output.checkpoint_interval so that there
is one near HALF before it), then PROGRAM --restart OUT/cut --from HALF: the
rows of probes.csv between HALF and STOP must be replaced, not repeated.
With --kill instead of STOP ("kill"), the cut run is killed with SIGKILL as
soon as a checkpoint at or after HALF exists, and restarted from its latest.
A third run without checkpoints (output.checkpoint_interval=0) must give
the same probes.csv rows (and iterations.csv, if the run writes one) as the first. Then every data row of probes.csv, every snapshot's particle fields and
time/step attributes, and the XDMF indexes must be identical between
OUT/full and OUT/cut, and so must iterations.csv and the iteration counts
of summary.json (implicit coupling); the restart's summary.json must say
where it restarted, and each solver's per-step figures (PCG iterations, time,
sub-steps) must be over the steps its restarted process ran.
--require COLUMN: the column must be > 0 at the checkpoint restarted from
(e.g. broken_bonds: the checkpoint holds a fractured solid).
Exit 0 if all hold, 1 with the first difference otherwise."""
import glob
import json
import os
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np


def fail(msg):
    print("restart_check: FAIL: " + msg)
    sys.exit(1)


def run(cmd, **kw):
    print("+ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, **kw)
    if r.returncode != 0:
        fail("exit %d from %s" % (r.returncode, " ".join(cmd)))


def rows(path):
    with open(path) as f:
        return [ln for ln in f if not ln.startswith("#")]


def same_rows(name, ra, rb):
    if ra != rb:
        n = next((k for k, (x, y) in enumerate(zip(ra, rb)) if x != y), min(len(ra), len(rb)))
        fail("%s: %d rows against %d, first difference at data row %d:\n  %s  %s"
             % (name, len(ra), len(rb), n, ra[n] if n < len(ra) else "(none)\n",
                rb[n] if n < len(rb) else "(none)"))


def ckpt_time(path):
    with open(path, "rb") as f:
        head = f.read(32)
    return np.frombuffer(head[16:24], dtype=np.float64)[0]


def compare_h5(a, b):
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        for k in ("time", "step"):
            if fa.attrs[k] != fb.attrs[k]:
                fail("%s: attribute %s %r != %r" % (b, k, fa.attrs[k], fb.attrs[k]))
        ga, gb = fa["particles"], fb["particles"]
        if sorted(ga.keys()) != sorted(gb.keys()):
            fail("%s: fields %s != %s" % (b, sorted(ga.keys()), sorted(gb.keys())))
        for name in ga.keys():
            x, y = ga[name][()], gb[name][()]
            if x.shape != y.shape or x.tobytes() != y.tobytes():
                bad = np.argwhere(x != y) if x.shape == y.shape else "shape"
                fail("%s: field %s differs (%s)" % (b, name, bad[:3] if len(bad) else bad))
        return len(ga.keys())


def check_rates(cut):
    """A restarted solver's per-step figures are over the steps its process
    ran (its counters and timers start at the restart), not over the steps
    since the run's start: a restart from half-way once read 6.4 PCG
    iterations a step where the run took 12.0. Returns the lines checked."""
    said = []

    def near(a, b):
        return abs(a - b) <= 1e-9 * max(abs(a), abs(b), 1e-300)

    def steps_run(name, s, rs):
        run = s.get("steps_run")
        if run is None or "step" not in rs or run != s["steps"] - rs["step"] or run <= 0:
            fail("%s: steps_run %r, steps %r, restart step %r: steps_run must be the steps "
                 "after the restart" % (name, run, s["steps"], rs.get("step")))
        return run

    for name in ("summary.json", "fluid_summary.json", "solid_summary.json"):
        path = os.path.join(cut, name)
        if not os.path.exists(path):
            continue
        with open(path) as f:
            s = json.load(f)
        rs = s.get("restart") or {}
        if "ppe_iterations" in s:  # the fluid, alone or coupled
            run = steps_run(name, s, rs)
            if not near(s["ppe_iterations_per_step"], s["ppe_iterations"] / run):
                fail("%s: ppe_iterations_per_step %r, not ppe_iterations / steps_run = %r"
                     % (name, s["ppe_iterations_per_step"], s["ppe_iterations"] / run))
            said.append("%s: %d steps run of %d, %.2f PCG iterations a step"
                        % (name, run, s["steps"], s["ppe_iterations_per_step"]))
        elif "substeps_per_coupling_step" in s:  # the solid, coupled
            if "substeps" not in rs or not 0 < rs["substeps"] < s["substeps"]:
                fail("%s: restart substeps %r against %r in all" % (name, rs.get("substeps"),
                                                                     s["substeps"]))
            want = (s["substeps"] - rs["substeps"]) / s["advances"]
            if not near(s["substeps_per_coupling_step"], want):
                fail("%s: substeps_per_coupling_step %r, not (substeps - the restart's) / "
                     "advances = %r" % (name, s["substeps_per_coupling_step"], want))
            said.append("%s: %.3f sub-steps an advance over %d advances"
                        % (name, want, s["advances"]))
        elif s.get("solver") == "solid_solver":  # the solid alone
            run = steps_run(name, s, rs)
            want = 1e9 * s["step_seconds"] / (s["particles"] * run)
            if not near(s["ns_per_particle_step"], want):
                fail("%s: ns_per_particle_step %r, not over the steps run: %r"
                     % (name, s["ns_per_particle_step"], want))
            said.append("%s: %d steps run of %d" % (name, run, s["steps"]))
    if not said:
        fail("no solver summary with per-step figures in %s" % cut)
    return said


def kill_after_checkpoint(cmd, cut, half, prefix):
    """Starts cmd, SIGKILLs it once a checkpoint at or after half exists."""
    print("+ " + " ".join(cmd) + "   (killed after a checkpoint at t >= %g)" % half, flush=True)
    p = subprocess.Popen(cmd)
    deadline = time.time() + 120
    while time.time() < deadline:
        done = [c for c in glob.glob(os.path.join(cut, "checkpoint", prefix + "_*.ckpt"))
                if ckpt_time(c) >= half]
        if done:
            break
        if p.poll() is not None:
            fail("the run ended (exit %d) before its checkpoint at %g" % (p.returncode, half))
        time.sleep(0.005)
    else:
        p.kill()
        fail("no checkpoint at t >= %g within 120 s" % half)
    children = subprocess.run(["pgrep", "-P", str(p.pid)], capture_output=True,
                              text=True).stdout.split()
    p.send_signal(signal.SIGKILL)
    p.wait()
    if p.poll() != -signal.SIGKILL:
        fail("the run was not killed (exit %s)" % p.returncode)
    # the solvers notice the coupler is gone and exit by themselves
    t0 = time.time()
    alive = children
    while alive and time.time() - t0 < 10:
        alive = [c for c in alive if os.path.exists("/proc/" + c) and
                 open("/proc/%s/stat" % c).read().split()[2] != "Z"]
        time.sleep(0.05)
    if alive:
        for c in alive:
            os.kill(int(c), signal.SIGKILL)
        fail("solver processes %s still alive 10 s after the coupler was killed" % alive)
    print("killed at a checkpoint t >= %g; %d solver process(es) exited in %.2f s"
          % (half, len(children), time.time() - t0))


def main():
    args = sys.argv[1:]
    require = None
    if "--require" in args:
        i = args.index("--require")
        require = args[i + 1]
        del args[i:i + 2]
    if len(args) < 5:
        print(__doc__)
        sys.exit(2)
    out, half, stop, prog, case = args[0], float(args[1]), args[2], args[3], args[4]
    extra = args[5:]
    prefix = {"fluid_solver": "fluid", "solid_solver": "solid"}.get(os.path.basename(prog),
                                                                    "coupler")
    shutil.rmtree(out, ignore_errors=True)
    full, cut = os.path.join(out, "full"), os.path.join(out, "cut")
    run([prog, case, "--out", full, "--quiet"] + extra)
    if stop == "kill":
        kill_after_checkpoint([prog, case, "--out", cut, "--quiet"] + extra, cut, half, prefix)
        run([prog, "--restart", cut, "--quiet"])
    else:
        run([prog, case, "--out", cut, "--quiet", "--stop-at", stop] + extra)
        cut_rows = len(rows(os.path.join(cut, "probes.csv")))
        if cut_rows >= len(rows(os.path.join(full, "probes.csv"))):
            fail("--stop-at %s did not stop the run (%d rows)" % (stop, cut_rows))
        run([prog, "--restart", cut, "--from", str(half), "--quiet"])

    # checkpoints must not change the run: the same without them
    nock = os.path.join(out, "nock")
    run([prog, case, "--out", nock, "--quiet"] + extra + ["--set", "output.checkpoint_interval=0"])
    if rows(os.path.join(full, "probes.csv")) != rows(os.path.join(nock, "probes.csv")):
        fail("probes.csv differs between the run with checkpoints and the run without")
    ra, rb = rows(os.path.join(full, "probes.csv")), rows(os.path.join(cut, "probes.csv"))
    same_rows("probes.csv", ra, rb)
    # implicit coupling: its log (coupling.implicit.log) and its counters
    iters = os.path.join(full, "iterations.csv")
    if os.path.exists(iters):
        ia = rows(iters)
        if ia != rows(os.path.join(nock, "iterations.csv")):
            fail("iterations.csv differs between the run with checkpoints and the run without")
        same_rows("iterations.csv", ia, rows(os.path.join(cut, "iterations.csv")))
        print("iterations.csv: %d rows identical" % (len(ia) - 1))
    # (the coupler's summary; a solver alone has none)
    with open(os.path.join(full, "summary.json")) as f:
        ita = json.load(f).get("iterations", {})
    with open(os.path.join(cut, "summary.json")) as f:
        itb = json.load(f).get("iterations", {})
    counts = {k: v for k, v in ita.items() if not k.endswith("seconds")}  # not timings
    if counts != {k: itb.get(k) for k in counts}:
        fail("summary.json iterations: %r against %r" % (counts, itb))
    snaps = sorted(os.path.basename(p) for p in glob.glob(os.path.join(full, "*.h5")))
    snaps_b = sorted(os.path.basename(p) for p in glob.glob(os.path.join(cut, "*.h5")))
    if snaps != snaps_b or not snaps:
        fail("snapshots %s != %s" % (snaps, snaps_b))
    nfields = sum(compare_h5(os.path.join(full, s), os.path.join(cut, s)) for s in snaps)
    for x in sorted(glob.glob(os.path.join(full, "*.xmf"))):
        with open(x) as fa, open(os.path.join(cut, os.path.basename(x))) as fb:
            if fa.read() != fb.read():
                fail("%s differs" % os.path.basename(x))
    with open(os.path.join(cut, "summary.json")) as f:
        summ = json.load(f)
    rs = summ.get("restart")
    if not rs or not os.path.exists(rs["checkpoint"]) and stop != "kill":
        fail("summary.json does not record the restart: %r" % rs)
    for line in check_rates(cut):
        print(line)
    kept = glob.glob(os.path.join(cut, "checkpoint", "*_*.ckpt"))
    per = {}
    for k in kept:
        per.setdefault(os.path.basename(k).rsplit("_", 1)[0], []).append(k)
    if any(len(v) > 2 for v in per.values()):
        fail("more than two checkpoints kept: %s" % sorted(kept))
    if require:
        head = ra[0].strip().split(",")
        if require not in head:
            fail("no column %s in probes.csv" % require)
        c = head.index(require)
        at = [ln.split(",") for ln in ra[1:] if float(ln.split(",")[0]) <= rs["time"] + 1e-12]
        if not at or not float(at[-1][c]) > 0:
            fail("%s is %s at the checkpoint (t = %g): not > 0" %
                 (require, at[-1][c] if at else "?", rs["time"]))
        print("%s = %s at the checkpoint t = %.9g" % (require, at[-1][c], rs["time"]))
    print("restart_check: OK: restarted at t = %.9g; %d probes.csv rows, %d snapshots "
          "(%d fields), %d .xmf identical" % (rs["time"], len(ra) - 1, len(snaps), nfields,
                                               len(glob.glob(os.path.join(full, "*.xmf")))))


if __name__ == "__main__":
    main()
