#!/usr/bin/python3
"""Cantilever beam (paper 5.1, Table 1) with the MPS solid, and its speed.

Runs cases/cantilever_beam/case.yml at several b/dp over two periods (1.7 s),
extracts the frequency and the maximum tip deflection (tests/solid/
cantilever_check.py), then times the bond loop at b/dp = 20 on 1 and 2 OpenMP
threads, and writes docs/solid_cantilever.md (+ docs/img/solid_cantilever.png).

usage: bench/solid_cantilever.py [--bin build/bin/solid_solver] [--ratios 5,10,20]
                                 [--threads 2] [--strain 5,10] [--speed-steps 3000]
                                 [--model NAME]
--model runs another solid model (solid_solver --model NAME, e.g. tlsph) into
OUT/NAME; the default is the case's model (mps) and docs/solid_cantilever.md.
Run from the repository root on a quiet machine."""
import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests",
                                "solid"))
import cantilever_check  # noqa: E402

CASE = "cases/cantilever_beam/case.yml"
B = 0.1
PAPER = {5: (1.27, 44.70, 5.07), 10: (1.27, 45.30, 3.80), 20: (1.27, 45.90, 2.53),
         40: (1.27, 46.27, 1.74), 80: (1.27, 46.45, 1.36)}
# Geometrically exact Euler-Bernoulli beam under the same sudden load
# (bench/solid_elastica_ref.py): what a converged 2D plane-stress model
# should approach; Eq. 53-54 are linear.
NONLINEAR_REF = (1.287, 46.61)


def run(binary, out, sets, threads, quiet=True, reuse=False, model=None):
    if reuse and os.path.isfile(os.path.join(out, "summary.json")):
        with open(os.path.join(out, "summary.json")) as f:
            return json.load(f), 0.0
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    cmd = [binary, CASE, "--out", out] + sum((["--set", s] for s in sets), [])
    if model:
        cmd += ["--model", model]
    if quiet:
        cmd.append("--quiet")
    t0 = time.time()
    subprocess.run(cmd, check=True, env=env)
    wall = time.time() - t0
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f), wall


def cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="build/bin/solid_solver")
    ap.add_argument("--ratios", default="5,10,20")
    ap.add_argument("--strain", default="5,10", help="b/dp also run in plane strain")
    ap.add_argument("--threads", type=int, default=2, help="threads for the table runs")
    ap.add_argument("--speed-steps", type=int, default=3000)
    ap.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "solid_cantilever"),
                    help="directory for the runs")
    ap.add_argument("--reuse", action="store_true",
                    help="use runs already in --out (summary.json present) instead of rerunning")
    ap.add_argument("--doc", default="docs/solid_cantilever.md")
    ap.add_argument("--model", help="solid model to run (default: the case's, mps)")
    a = ap.parse_args()
    if a.model:
        a.out = os.path.join(a.out, a.model)
    ratios = [int(r) for r in a.ratios.split(",") if r]
    strain = [int(r) for r in a.strain.split(",") if r]
    os.makedirs(a.out, exist_ok=True)

    rows = []
    for plane, rs in (("stress", ratios), ("strain", strain)):
        for r in rs:
            dp = B / r
            out = os.path.join(a.out, f"{plane}_b{r}")
            s, _ = run(a.bin, out, [f"dp={dp:.10g}", f"solid.plane={plane}",
                                    "output.interval=0.1"], a.threads, reuse=a.reuse,
                   model=a.model)
            res = cantilever_check.analyse(os.path.join(out, "probes.csv"))
            rows.append(dict(plane=plane, ratio=r, dp=dp, n=s["particles"], steps=s["steps"],
                             t_end=s["time"],
                             wall=s["step_seconds"], pss=s["particle_steps_per_second"],
                             dt=s["solid"]["dt_stable"], **res, out=out))
            print(f"plane {plane} b/dp {r}: f {res['f']:.4f} Hz ({res['f_err_pct']:+.2f}%), "
                  f"max {res['dmax_cm']:.2f} cm (disc {res['disc_pct']:+.2f}%), "
                  f"{s['step_seconds']:.1f} s", flush=True)

    # Speed: the bond loop at b/dp = 20, best of 3 short runs per thread count.
    speed = {}
    load = open("/proc/loadavg").read().split()[:3] if os.path.exists("/proc/loadavg") else []
    probe, _ = run(a.bin, os.path.join(a.out, "speed_dt"),
                   ["dp=0.005", "end_time=1e-5", "output.interval=0"], 1, model=a.model)
    end = a.speed_steps * probe["solid"]["dt_stable"]
    for th in (1, 2):
        best = None
        for _ in range(3):
            s, _ = run(a.bin, os.path.join(a.out, f"speed_t{th}"),
                       ["dp=0.005", f"end_time={end:.6g}", "output.interval=0",
                        "output.probe_interval=1"], th, model=a.model)
            ns = s["ns_per_particle_step"]
            if best is None or ns < best[0]:
                best = (ns, s)
        speed[th] = best
        print(f"speed b/dp 20, {th} thread(s): {best[0]:.1f} ns per particle-step", flush=True)

    png = f"solid_cantilever_{a.model}.png" if a.model else "solid_cantilever.png"
    plot = make_plot(rows, os.path.join(os.path.dirname(a.doc), "img", png))
    write_doc(a, rows, speed, plot, load)
    print("wrote", a.doc)


def make_plot(rows, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
    except ImportError:
        return None
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig, ax = plt.subplots(figsize=(8, 4))
    for r in rows:
        with open(os.path.join(r["out"], "probes.csv")) as f:  # '#' lines: provenance
            d = np.genfromtxt((l for l in f if not l.startswith("#")), delimiter=",", names=True)
        ls = "-" if r["plane"] == "stress" else ":"
        ax.plot(d["time"], 100 * d["tip_dy"], ls, label=f"b/dp = {r['ratio']} ({r['plane']})")
    ax.axhline(-47.09, color="k", lw=0.8, ls="--", label="Eq. 53 x 2 (-47.09 cm)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("tip deflection (cm)")
    ax.legend(fontsize=8, ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def write_doc(a, rows, speed, plot, load):
    cmd = (f"bench/solid_cantilever.py --bin {a.bin} --ratios {a.ratios} --strain {a.strain} "
           f"--threads {a.threads}" + (f" --model {a.model}" if a.model else "") +
           (" --reuse" if a.reuse else ""))
    L = []
    name = (a.model or "mps").upper()
    L.append(f"# Cantilever beam (paper section 5.1) with the {name} solid\n")
    L.append("Generated by `" + cmd + "` (" + time.strftime("%Y-%m-%d") + ", " + cpu_name() +
             f", {os.cpu_count()} cores). Case: `{CASE}` (l = 2 m, b = 0.1 m, rho = 1000 kg/m^3, "
             "E = 100 MPa, nu = 0.3, gravity applied suddenly at t = 0, clamped by 3+ layers of "
             "fixed particles beyond the root), run for 1.7 s (a little over two periods); the tip probe is "
             "the centre of the free end (mean of the two middle rows when b/dp is even).\n")
    L.append("Reference (Eq. 53-54, I = b^3/12 per metre depth): f = 1.277 Hz, maximum "
             "deflection 47.09 cm (twice the static one). f is from the zero crossings of "
             "tip_dy - mean; the maximum deflection is max |tip_dy|; the discrepancy is "
             "(47.09 - max) / 47.09, as in the paper's Table 1 (negative: larger than 47.09).\n")
    L.append("## Table 1, plane stress (the case's `solid.plane: stress`)\n")
    L.append("| b/dp | dp (mm) | particles | f (Hz) | f error | max deflection (cm) | "
             "discrepancy | paper: f, max, discrepancy | steps | wall (s) | "
             "particle-steps/s |")
    L.append("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if r["plane"] != "stress":
            continue
        p = PAPER.get(r["ratio"])
        ps = f"{p[0]:.2f}, {p[1]:.2f}, {p[2]:.2f}%" if p else "-"
        L.append(f"| {r['ratio']} | {1000 * r['dp']:.2f} | {r['n']} | {r['f']:.4f} | "
                 f"{r['f_err_pct']:+.2f}% | {r['dmax_cm']:.2f} | {r['disc_pct']:+.2f}% | {ps} | "
                 f"{r['steps']} | {r['wall']:.1f} | {r['pss']:.3g} |")
    L.append(f"| analytical (linear) | | | 1.2769 | | 47.09 | | 1.27, 47.09 | | | |")
    L.append(f"| geometrically exact beam | | | {NONLINEAR_REF[0]:.3f} | | {NONLINEAR_REF[1]:.2f} "
             "| | | | | |\n")
    L.append(f"Wall time is the stepping loop only, on {a.threads} OpenMP thread(s) (below "
             "4096 particles the loops run on one thread: b/dp = 5 and 10 are serial).\n")
    odd = [r for r in rows if abs(r["t_end"] - rows[0]["t_end"]) > 1e-9]
    for r in odd:
        L.append(f"The b/dp = {r['ratio']} ({r['plane']}) run ended at t = {r['t_end']:g} s "
                 f"({r['periods']:.2f} periods).\n")
    if any(r["plane"] == "strain" for r in rows):
        L.append("## Plane strain (Eq. 4 as printed, `solid.plane: strain`)\n")
        L.append("| b/dp | f (Hz) | f error | max deflection (cm) | discrepancy |")
        L.append("|---|---|---|---|---|")
        for r in rows:
            if r["plane"] == "strain":
                L.append(f"| {r['ratio']} | {r['f']:.4f} | {r['f_err_pct']:+.2f}% | "
                         f"{r['dmax_cm']:.2f} | {r['disc_pct']:+.2f}% |")
        L.append("")
    L.append("## Speed (b/dp = 20, 8240 particles, best of 3 runs of "
             f"{a.speed_steps} steps)\n")
    L.append("| OpenMP threads | ns per particle-step | particle-steps/s | strain / force / "
             "update (s) |")
    L.append("|---|---|---|---|")
    for th, (ns, s) in sorted(speed.items()):
        ph = s["solid"]["phase_seconds"]
        L.append(f"| {th} | {ns:.1f} | {s['particle_steps_per_second']:.3g} | "
                 f"{ph['strain']:.2f} / {ph['force']:.2f} / {ph['update']:.2f} |")
    if 1 in speed and 2 in speed:
        L.append(f"\nSpeed-up on 2 threads: {speed[1][0] / speed[2][0]:.2f}x. Load average "
                 f"before the speed runs: {' '.join(load)} (other jobs on the machine slow the "
                 "2-thread runs most: a thread that loses its core stalls the other at every "
                 "barrier).\n")
    if plot:
        L.append(f"![tip deflection](img/{os.path.basename(plot)})\n")
    if (a.model or "mps") == "mps":  # the notes discuss the MPS model
        L.append(open(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                   "solid_cantilever_notes.md")).read())
    os.makedirs(os.path.dirname(a.doc), exist_ok=True)
    with open(a.doc, "w") as f:
        f.write("\n".join(L))


if __name__ == "__main__":
    main()
