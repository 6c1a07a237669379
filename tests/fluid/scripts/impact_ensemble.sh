#!/bin/sh
# The coarse version of bench/impact_ensemble.py (docs/pressure.md, "Impact
# pressure on the wall"): four realisations of the 8 mm dam break to 0.35 s,
# each from a lattice jittered by 1e-3 dp with its own seed. Every one must
# see a physical impact on the right-wall sensor (check_sensors.py's bounds:
# after the front arrives, at least rho U^2 / 2 and 3 x hydrostatic, at most
# rho c U), and the four must be four draws: their peaks not all the same
# (a seed that changed nothing would give one run four times).
# usage: impact_ensemble.sh SOLVER_BUILD OUT_DIR
build=$1; out=$2
rm -rf "$out"
/usr/bin/python3 bench/impact_ensemble.py --build "$build" --dps 0.008:4 --end 0.35 \
    --out "$out" --json "$out/ensemble.json" \
    --set fluid.probes.6.name=h_wall --set fluid.probes.6.kind=height \
    --set fluid.probes.6.x=0.576 || exit 1
for s in 1 2 3 4; do
    /usr/bin/python3 "$(dirname "$0")/../check_sensors.py" "$out/db_0.008_s$s" --check dambreak \
        --dp 0.008 || exit 1
done
exec /usr/bin/python3 - "$out/ensemble.json" <<'PY'
import json, sys
e = json.load(open(sys.argv[1]))['dps']['0.008']
peaks = [m['peak'] for m in e['metrics']]
print('peaks of the four realisations (Pa):', ', '.join('%.0f' % p for p in peaks),
      '; mean %.0f +- %.0f' % (e['peak']['mean'], e['peak']['se']))
ok = len(set(peaks)) == len(peaks)
print(('PASS' if ok else 'FAIL') + ': the seeds give distinct realisations')
sys.exit(0 if ok else 1)
PY
