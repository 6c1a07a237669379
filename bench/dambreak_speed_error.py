#!/usr/bin/python3
"""Dam break speed against error: Martin & Moyce errors next to wall time.

usage: bench/dambreak_speed_error.py [--bin build/bin] [--dps 0.008,0.004,0.002]
           [--threads 2] [--end 0.27]
Runs cases/dambreak at each spacing to t = end (T = 3 at 0.26 s) without
snapshots and prints one markdown row per run: particles, steps, wall time,
us per particle-step, the front's max and mean error against the
measurements (table points up to T = 3), the same with the measurements
taken 0.2 later in T (17 ms: the release time of the gate, docs/fluid.md),
and the height error at the wall. Run it on a quiet machine."""
import argparse, math, os, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'bench'))
import dambreak_compare as dc  # noqa: E402

A = 0.146  # column width, m
SHIFT_T = 0.2  # release delay in T units (docs/fluid.md)


def shifted_front(run, tmax=3.0):
    pr = dc.load_probes(run)
    s = math.sqrt(2 * 9.81 / A)
    errs = []
    for T, Z in dc.load_ref()['mm_table_T_Z']:
        if T > tmax:
            continue
        x = dc.interp(pr['time'], pr['front'], (T - SHIFT_T) / s)
        errs.append(((x if x is not None else pr['front'][0]) / A - Z) / Z)
    return max(map(abs, errs)), sum(map(abs, errs)) / len(errs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--bin', default=os.path.join(ROOT, 'build', 'bin'))
    ap.add_argument('--dps', default='0.008,0.004,0.002')
    ap.add_argument('--threads', type=int, default=2)
    ap.add_argument('--end', type=float, default=0.27)
    a = ap.parse_args()
    print('| dp (mm) | particles (fluid / all) | steps | wall s | us/particle-step | '
          'front max / mean error | same, measurements 17 ms later | height max / mean error |')
    print('|---|---|---|---|---|---|---|---|')
    for dp in (float(d) for d in a.dps.split(',')):
        out, s, ok, _ = dc.run_dambreak(a.bin, a.threads, [f'dp={dp}', f'end_time={a.end}'],
                                        prefix='dbse_')
        if not ok:
            print(f'| {dp * 1e3:g} | run failed, see {out} |')
            continue
        r = dc.compare(out, A, 3.0)
        smax, smean = shifted_front(out)
        p = s['particles']
        print(f"| {dp * 1e3:g} | {p['fluid']} / {p['total']} | {s['steps']} | "
              f"{s['wall_seconds']:.1f} | {s['ns_per_particle_step'] / 1e3:.2f} | "
              f"{100 * r['front_max_rel_err']:.1f}% / {100 * r['front_mean_rel_err']:.1f}% | "
              f"{100 * smax:.1f}% / {100 * smean:.1f}% | "
              f"{100 * r['height_max_rel_err']:.1f}% / {100 * r['height_mean_rel_err']:.1f}% |",
              flush=True)


if __name__ == '__main__':
    main()
