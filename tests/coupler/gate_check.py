#!/usr/bin/python3
"""Checks a coarse elastic-gate run (dp = 2.5 mm, the gate 2 particles thick,
to 0.2 s): the water column pushes the gate's free end open, downstream and
up, to a first peak, after which the gate closes as the column drains.

The band is the primary opening: the largest tip_dx up to 0.15 s must lie in
3.35-3.85 cm, reached at 0.085-0.125 s. Physics: at dp = 1 mm (5 particles
thick, docs/elastic_gate.md) the solids peak at 3.66-4.14 cm at 0.111-0.123 s
(MPS plane strain and quadratic TLSPH, the two consistent discretisations,
3.66 and 3.81 cm: 4% apart); the opening is driven by the column, and both
coarse solids, two different discretisations of the same 2-particle gate,
peak at 3.58-3.59 cm at 0.099-0.105 s (measured 2026-12-02, the same to 0.01 cm
with 1 and 2 threads and MPS_SIMD=sse2). The band is that value +-7%: the spread of the
consistent fine solids plus a margin. The peak is flat, so the time of its maximum
wanders: eight realisations from jittered starts (fluid.jitter 1e-3 dp, seeds 1-4, each
solid, one thread, 2026-12-03) peak at 3.52-3.57 cm but at 0.092-0.102 s (mean 0.098,
sd 0.004), and one variant of the fluid read 0.089 s (docs/pressure.md). The time band
starts at 0.085 s, three standard deviations under their mean (it was 0.09, two realisations
2 ms from it). Then, at 0.15 s, the gate is
closing (tip_dx below its peak), the end never goes down into the floor
(tip_dy >= -2 mm) and it swings up on its arc (tip_dy > 0 at the peak).

Before: the largest opening over the whole run within 2.2-5.8 cm, which a
gate 40% too stiff or too soft passed. What happens after 0.15 s is not
checked: the coarse MPS gate is kicked open again at 0.17-0.19 s by a load
spike (solid_fx 45 -> 440 N/m) that neither the TLSPH gate nor the 1 mm runs
show, and not with 1 thread (a chaotic splash; reported, left to the fluid's
owners)."""
import csv, os, sys

with open(os.path.join(sys.argv[1], 'probes.csv')) as f:
    rows = list(csv.DictReader(l for l in f if not l.startswith('#')))  # '#': provenance
t = [float(r['time']) for r in rows]
dx = [float(r['tip_dx']) for r in rows]
dy = [float(r['tip_dy']) for r in rows]
early = [i for i in range(len(t)) if t[i] <= 0.15 + 1e-9]
k = max(early, key=lambda i: dx[i])
at15 = min(range(len(t)), key=lambda i: abs(t[i] - 0.15))
checks = [
    (0.0335 <= dx[k] <= 0.0385, f"peak opening {100 * dx[k]:.2f} cm (band 3.35-3.85 cm)"),
    (0.085 <= t[k] <= 0.125, f"at {t[k]:.3f} s (band 0.085-0.125 s)"),
    (dx[at15] < dx[k], f"closing at 0.15 s: {100 * dx[at15]:.2f} cm"),
    (min(dy) >= -0.002, f"tip_dy min {1000 * min(dy):.2f} mm (>= -2 mm)"),
    (dy[k] > 0, f"tip_dy at the peak {100 * dy[k]:.2f} cm (> 0)"),
]
for ok, what in checks:
    print(('ok   ' if ok else 'FAIL ') + what)
print(f"(after 0.15 s, not checked: tip_dx max {100 * max(dx):.2f} cm, final {100 * dx[-1]:.2f} cm)")
sys.exit(0 if all(ok for ok, _ in checks) else 1)
