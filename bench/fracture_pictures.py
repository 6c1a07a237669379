#!/usr/bin/python3
"""Pictures and numbers of the collision with brittle fracture (paper 5.2, Fig. 5).

Runs cases/fracture_collision/case.yml twice at one dp, with solid.contact =
bodies (the paper's run without contact detection, Fig. 5 left) and all (with
it, right), then draws both at 0.07, 0.6, 0.7, 1.0 and 1.7 s, coloured by
body and surface flag (surface particles made by fracture in red, as in the
paper's Fig. 1), plots the diagnostics over time (broken bonds, smallest
distance between particles of different surfaces, momentum error) and prints
a markdown table of them.

usage: bench/fracture_pictures.py [--bin build/bin/solid_solver] [--dp 0.0125]
                                  [--out /tmp/fracture] [--img DIR] [--reuse]
       bench/fracture_pictures.py --timing [--bin ...] [--dp 0.0125] [--end 0.5]
                                  [--threads 1] [--repeat 3]
Writes IMG/fracture_collision_dpNNNN.png and IMG/fracture_diagnostics_dpNNNN.png
(IMG: --img, by default the --out directory; --img docs/img replaces the
pictures of docs/fracture.md).
--timing instead runs the case without fracture (solid.eps_max and
solid.contact removed), with fracture only (contact: none), and with contact
bodies and all, and prints the cost of each in ns per particle-step (best of
--repeat runs, stepping loop only, no snapshots).
Run from the repository root. Needs /usr/bin/python3 with h5py and matplotlib."""
import argparse
import csv
import glob
import json
import math
import os
import subprocess
import sys

import h5py
import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import EllipseCollection  # noqa: E402

CASE = "cases/fracture_collision/case.yml"
TIMES = [0.07, 0.6, 0.7, 1.0, 1.7]
MODES = [("bodies", "without contact detection (contact: bodies)"),
         ("all", "with contact detection (contact: all)")]
# inner, initial surface, surface made by fracture; per body (block, square)
COLOURS = [("#9ecae1", "#2171b5", "#e31a1c"), ("#f4a6e6", "#ae017e", "#e31a1c")]


def run(binary, out, dp, mode, reuse):
    done = os.path.join(out, "summary.json")
    if reuse and os.path.isfile(done):
        return
    cmd = [binary, CASE, "--out", out, "--quiet", "--set", "dp=%g" % dp,
           "--set", "solid.contact=%s" % mode]
    print("+", " ".join(cmd), file=sys.stderr)
    # a run that diverges still leaves its snapshots: report, do not stop
    r = subprocess.run(cmd)
    if r.returncode != 0:
        print("run %s ended with code %d" % (out, r.returncode), file=sys.stderr)


def snapshots(out):
    """(time, path) of every snapshot of a run, by time."""
    snaps = []
    for p in sorted(glob.glob(os.path.join(out, "solid_*.h5"))):
        with h5py.File(p, "r") as f:
            snaps.append((float(f.attrs["time"]), p))
    return sorted(snaps)


def read(path):
    with h5py.File(path, "r") as f:
        g = f["particles"]
        snap = {k: g[k][()] for k in ("position", "body", "surface", "id")}
    snap["position"] = snap["position"][:, :2]  # the files' vectors have 3 components, z = 0
    return snap


def draw(ax, snap, surf0, dp, body, window, title):
    """Particles of one body (both are drawn if they overlap the window), in a
    square window of side `window` centred on that body."""
    x = snap["position"]
    colours = []
    for b, s, i in zip(snap["body"], snap["surface"], snap["id"]):
        c = COLOURS[min(int(b), 1)]
        colours.append(c[0] if not s else (c[1] if surf0[i] else c[2]))
    ax.add_collection(EllipseCollection(
        [dp] * len(x), [dp] * len(x), [0] * len(x), units="xy", offsets=x,
        offset_transform=ax.transData, facecolors=colours, edgecolors="none"))
    cx, cy = centre(snap, body)
    ax.set_xlim(cx - 0.5 * window, cx + 0.5 * window)
    ax.set_ylim(cy - 0.5 * window, cy + 0.5 * window)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=7)
    ax.tick_params(labelsize=5)


def extent(snap, body):
    """Bounding box of the bulk of a body: 1% of its particles may lie
    outside (a few particles chipped off would otherwise set the scale)."""
    x = snap["position"][snap["body"] == body]
    return np.percentile(x, 0.5, axis=0), np.percentile(x, 99.5, axis=0)


def centre(snap, body):
    lo, hi = extent(snap, body)
    return 0.5 * (lo + hi)


def probes(out):
    with open(os.path.join(out, "probes.csv")) as f:
        rows = list(csv.DictReader(l for l in f if not l.startswith('#')))  # '#': provenance
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def stats(out, dp):
    p = probes(out)
    summ = None
    if os.path.isfile(os.path.join(out, "summary.json")):
        with open(os.path.join(out, "summary.json")) as f:
            summ = json.load(f)
    p0 = math.hypot(p["momentum_x"][0], p["momentum_y"][0])
    dmom = max(math.hypot(a - p["momentum_x"][0], b - p["momentum_y"][0])
               for a, b in zip(p["momentum_x"], p["momentum_y"]) if math.isfinite(a + b))
    gaps = [(g, t) for g, t in zip(p["min_gap"], p["time"]) if math.isfinite(g)]
    gmin, tmin = min(gaps)
    first = next((t for t, b in zip(p["time"], p["broken_bonds"]) if b > 0), None)
    return {
        "end": p["time"][-1], "finished": summ is not None,
        "broken": int(p["broken_bonds"][-1]), "first_break": first,
        "surface": int(p["surface_particles"][-1]),
        "gap_min": gmin / dp, "gap_t": tmin, "mom_err": dmom / p0,
        "ns": summ["ns_per_particle_step"] if summ else float("nan"),
        "particles": summ["particles"] if summ else None,
        "contact_gap": (summ["solid"]["fracture"]["contact_gap_min_over_l0"]
                        if summ else float("nan")),
    }


def table(outs, dp, header):
    """Markdown rows: one per run. min distance: the smallest distance of two
    particles not joined by an intact bond, sampled every probe interval
    (exact, all particles); in contact: the smallest distance of two touching
    listed particles, every step (summary.json)."""
    if header:
        print("| dp (m) | contact | particles | reached (s) | broken bonds (first at, s) | "
              "surface particles | min distance / l0 (at, s) | in contact, every step / l0 | "
              "max momentum error | ns/particle-step |")
        print("|---|---|---|---|---|---|---|---|---|---|")
    for mode, _ in MODES:
        s = stats(outs[mode], dp)
        print("| %g | %s | %s | %.3g%s | %d (%s) | %d | %.3f (%.3f) | %.3f | %.1e | %.0f |" % (
            dp, mode, s["particles"], s["end"], "" if s["finished"] else " (diverged)",
            s["broken"], "-" if s["first_break"] is None else "%.3f" % s["first_break"],
            s["surface"], s["gap_min"], s["gap_t"], s["contact_gap"], s["mom_err"], s["ns"]))


def timing(a):
    """Cost of fracture and contact: the same scene four ways."""
    os.makedirs(a.out, exist_ok=True)
    plain = os.path.join(a.out, "case_no_fracture.yml")
    with open(CASE) as f, open(plain, "w") as g:
        for line in f:
            if not line.lstrip().startswith(("eps_max:", "contact:")):
                g.write(line)
    variants = [("no fracture (keys absent)", plain, []),
                ("fracture, contact: none", CASE, ["solid.contact=none"]),
                ("fracture, contact: bodies", CASE, ["solid.contact=bodies"]),
                ("fracture, contact: all", CASE, ["solid.contact=all"])]
    env = dict(os.environ, OMP_NUM_THREADS=str(a.threads))
    print("| dp = %g m, to %g s, %d thread(s) | particles | steps | ns/particle-step | "
          "strain / force / update / contact (s) | broken bonds |" % (a.dp, a.end, a.threads))
    print("|---|---|---|---|---|---|")
    for name, case, sets in variants:
        best = None
        for r in range(a.repeat):
            out = os.path.join(a.out, "timing")
            cmd = [a.bin, case, "--out", out, "--quiet", "--set", "dp=%g" % a.dp,
                   "--set", "end_time=%g" % a.end, "--set", "output.interval=0",
                   "--set", "output.probe_interval=%g" % a.end]
            for x in sets:
                cmd += ["--set", x]
            subprocess.run(cmd, check=True, env=env)
            with open(os.path.join(out, "summary.json")) as f:
                summ = json.load(f)
            if best is None or summ["ns_per_particle_step"] < best["ns_per_particle_step"]:
                best = summ
        ph = best["solid"]["phase_seconds"]
        fr = best["solid"].get("fracture")
        print("| %s | %d | %d | %.1f | %s | %s |" % (
            name, best["particles"], best["steps"], best["ns_per_particle_step"],
            " / ".join("%.2f" % ph[k] if k in ph else "-"
                       for k in ("strain", "force", "update", "contact")),
            fr["broken_bonds"] if fr else "-"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="build/bin/solid_solver")
    ap.add_argument("--dp", type=float, default=0.0125)
    ap.add_argument("--timing", action="store_true")
    ap.add_argument("--end", type=float, default=0.5, help="--timing: end time, s")
    ap.add_argument("--threads", type=int, default=1, help="--timing: OpenMP threads")
    ap.add_argument("--repeat", type=int, default=3, help="--timing: runs of each")
    ap.add_argument("--out", default="/tmp/fracture")
    ap.add_argument("--img", help="where the pictures go (default: --out)")
    ap.add_argument("--reuse", action="store_true", help="keep runs that finished")
    ap.add_argument("--table-only", action="store_true",
                    help="only the table of runs already in OUT (no pictures)")
    a = ap.parse_args()
    if a.img is None:
        a.img = a.out
    if a.timing:
        return timing(a)
    tag = "dp%04d" % round(a.dp * 1e4)
    outs = {}
    for mode, _ in MODES:
        outs[mode] = os.path.join(a.out, "%s_%s" % (tag, mode))
        if not a.table_only:
            run(a.bin, outs[mode], a.dp, mode, a.reuse)
    if a.table_only:
        return table(outs, a.dp, header=True)

    # rows: times; columns: (square, block) of each run. Both runs at one
    # time share the scale (window: the larger body's extent, + 4 dp).
    fig, axes = plt.subplots(len(TIMES), 4, figsize=(10, 2.7 * len(TIMES)))
    runs = []
    for mode, label in MODES:
        snaps = snapshots(outs[mode])
        first = read(snaps[0][1])
        runs.append((mode, label, snaps, dict(zip(first["id"], first["surface"]))))
    for row, t in enumerate(TIMES):
        shown = []
        for mode, label, snaps, surf0 in runs:
            tt, path = min(snaps, key=lambda s: abs(s[0] - t))
            shown.append((tt, read(path)) if abs(tt - t) <= 0.006 else (snaps[-1][0], None))
        for body, name in ((1, "square"), (0, "block")):
            window = max([max(hi - lo) for _, snap in shown if snap is not None
                          for lo, hi in [extent(snap, body)]] or [0.0]) + 4 * a.dp
            for k, ((mode, label, _, surf0), (tt, snap)) in enumerate(zip(runs, shown)):
                ax = axes[row][2 * k + (0 if body == 1 else 1)]
                if snap is None:
                    ax.set_title("%s\nt = %g s: no snapshot (run ended at %.3g s)"
                                 % (label, t, tt), fontsize=7)
                    ax.axis("off")
                    continue
                draw(ax, snap, surf0, a.dp, body, window,
                     "%s: %s\nt = %.2f s" % ("no contact" if mode == "bodies" else "contact",
                                              name, tt))
    fig.suptitle("Collision with brittle fracture, dp = %g m: blue block, magenta square,\n"
                 "dark: surface at start, red: surface made by fracture "
                 "(left pair: contact: bodies, the paper's run without contact detection;\nright pair: contact: all; each view follows one body)" % a.dp, fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    os.makedirs(a.img, exist_ok=True)
    pics = os.path.join(a.img, "fracture_collision_%s.png" % tag)
    fig.savefig(pics, dpi=90)
    plt.close(fig)

    fig, ax = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    for mode, label in MODES:
        p = probes(outs[mode])
        p0 = math.hypot(p["momentum_x"][0], p["momentum_y"][0])
        ax[0].plot(p["time"], p["broken_bonds"], label=label)
        ax[1].plot(p["time"], [g / a.dp for g in p["min_gap"]], label=label)
        ax[2].plot(p["time"], [max(1e-18, math.hypot(x - p["momentum_x"][0],
                                                     y - p["momentum_y"][0]) / p0)
                               for x, y in zip(p["momentum_x"], p["momentum_y"])], label=label)
    ax[0].set_ylabel("broken bonds")
    ax[1].set_ylabel("min distance, different\nsurfaces / l0 (up to 2)")
    ax[1].axhline(0.5, color="k", lw=0.6, ls="--")
    ax[2].set_ylabel("|P - P0| / |P0|\n(zero drawn at 1e-18)")
    ax[2].set_yscale("log")
    ax[2].set_ylim(1e-18, 1e-2)
    ax[2].set_xlabel("t (s)")
    ax[0].legend(fontsize=7)
    fig.suptitle("Collision with brittle fracture, dp = %g m" % a.dp, fontsize=9)
    fig.tight_layout()
    diag = os.path.join(a.img, "fracture_diagnostics_%s.png" % tag)
    fig.savefig(diag, dpi=110)
    plt.close(fig)

    table(outs, a.dp, header=True)
    print("\nwrote %s, %s" % (pics, diag), file=sys.stderr)


if __name__ == "__main__":
    main()
