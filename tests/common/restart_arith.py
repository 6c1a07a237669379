#!/usr/bin/python3
"""A restart with other arithmetic says so (docs/restart.md, "Other arithmetic").

  restart_arith.py OUT STOP PREFIX THREADS_COUNT PROGRAM CASE [ARGS...]

PREFIX: the checkpoint's prefix (fluid, solid). THREADS_COUNT: yes if the
program's sums depend on the OpenMP thread count and the vector paths (the
fluid), no if on neither (the solid). ARGS must set output.checkpoint_interval so that a checkpoint falls
at or after STOP.

Runs PROGRAM CASE ARGS with 2 threads to the end (OUT/full) and stopped at
STOP (OUT/cut), then restarts copies of OUT/cut (each with --quiet):
  same   2 threads: no note; probes.csv as OUT/full's, bit for bit;
  other  1 thread: THREADS_COUNT yes: one note naming the checkpoint and
         "threads 2 -> 1", summary.json restart.arith_differs the same;
         no: no note, and probes.csv as OUT/full's (the claim that the
         thread count does not change the run);
  older  1 thread, the checkpoint's "arith" block dropped (a checkpoint of a
         build before it): restarts, no note;
  sse2   MPS_SIMD=sse2, 2 threads: THREADS_COUNT yes, where the first run
         took the AVX-512 paths (the fluid's summary says simd_paths), the
         note names "paths avx512 -> portable" (skipped with a line on a CPU
         without them); no: no note, and probes.csv as OUT/full's.
Exit 0 if all hold, 1 with the first failure."""
import glob
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
NOTE = "note: "


def fail(msg):
    print("restart_arith: FAIL: " + msg)
    sys.exit(1)


def run(cmd, threads, extra_env=None):
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    env.pop("MPS_SIMD", None)
    env.update(extra_env or {})
    print("+ OMP_NUM_THREADS=%d %s%s" % (threads, "".join(
        "%s=%s " % kv for kv in (extra_env or {}).items()), " ".join(cmd)), flush=True)
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    sys.stdout.write(r.stderr)
    if r.returncode != 0:
        fail("exit %d from %s" % (r.returncode, " ".join(cmd)))
    return [ln for ln in r.stderr.splitlines() if NOTE in ln]


def rows(out):
    with open(os.path.join(out, "probes.csv")) as f:
        return [ln for ln in f if not ln.startswith("#")]


def summary(out):
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def restart(out, cut, name, threads, extra_env=None, drop_arith=False):
    d = os.path.join(out, name)
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(cut, d)
    if drop_arith:
        for ck in glob.glob(os.path.join(d, "checkpoint", "*.ckpt")):
            subprocess.run(["/usr/bin/python3", os.path.join(HERE, "ckpt_cut.py"), ck, "arith",
                            "--only"], check=True)
    notes = run([PROGRAM, "--restart", d, "--quiet"], threads, extra_env)
    return d, notes, summary(d).get("restart", {})


def no_note(name, notes, rs):
    if notes or "arith_differs" in rs:
        fail("%s: a note where the arithmetic is the checkpoint's: %s %s" % (name, notes, rs))


def one_note(name, notes, rs, want):
    if len(notes) != 1:
        fail("%s: %d note lines, expected 1" % (name, len(notes)))
    line = notes[0]
    if not (PREFIX + "_0" in line and ".ckpt was written with other arithmetic (" + want in line
            and "docs/restart.md" in line):
        fail("%s: the note does not name the checkpoint and '%s': %s" % (name, want, line))
    if not rs.get("arith_differs", "").startswith(want):
        fail("%s: summary.json restart.arith_differs = %r, expected %r"
             % (name, rs.get("arith_differs"), want))


def main():
    global PROGRAM, PREFIX
    if len(sys.argv) < 7:
        sys.exit(__doc__)
    out, stop, PREFIX, threads_count, PROGRAM, case = sys.argv[1:7]
    args = sys.argv[7:]
    full, cut = os.path.join(out, "full"), os.path.join(out, "cut")
    for d in (full, cut):
        shutil.rmtree(d, ignore_errors=True)
    run([PROGRAM, case] + args + ["--out", full, "--quiet"], 2)
    run([PROGRAM, case] + args + ["--out", cut, "--quiet", "--stop-at", stop], 2)
    ref = rows(full)

    d, notes, rs = restart(out, cut, "same", 2)
    no_note("same", notes, rs)
    if rows(d) != ref:
        fail("same: the restart with the checkpoint's arithmetic is not the run, bit for bit")

    d, notes, rs = restart(out, cut, "other", 1)
    if threads_count == "yes":
        one_note("other", notes, rs, "threads 2 -> 1")
        print("other: %s" % ("probes.csv differs from the run's, as the note says it may"
                             if rows(d) != ref else "probes.csv happens to be the run's"))
    else:
        no_note("other", notes, rs)
        if rows(d) != ref:
            fail("other: one thread gave another run, but the program says its thread count "
                 "does not count")

    d, notes, rs = restart(out, cut, "older", 1, drop_arith=True)
    no_note("older", notes, rs)

    simd = summary(full).get("simd_paths")
    if threads_count == "no":
        d, notes, rs = restart(out, cut, "sse2", 2, {"MPS_SIMD": "sse2"})
        no_note("sse2", notes, rs)
        if rows(d) != ref:
            fail("sse2: the portable paths gave another run, but the program says its "
                 "paths do not count")
    elif simd == "avx512":
        d, notes, rs = restart(out, cut, "sse2", 2, {"MPS_SIMD": "sse2"})
        one_note("sse2", notes, rs, "paths avx512 -> portable")
    else:
        print("sse2: skipped (the first run took the %s paths)" % simd)
    print("restart_arith: ok")


if __name__ == "__main__":
    main()
