#!/bin/sh
# The 8 mm dam break to 0.3 s with three output schedules: no snapshot may
# flicker, and all three must have the same probes.csv (check_flicker.py).
# usage: flicker.sh SOLVER OUT_DIR
solver=$1; out=$2
rm -rf "$out"
for iv in 0.0199 0.02 0.01; do
    "$solver" cases/dambreak/case.yml --out "$out/iv$iv" --quiet --set dp=0.008 \
        --set end_time=0.3 --set output.interval=$iv || exit 1
done
exec /usr/bin/python3 "$(dirname "$0")/../check_flicker.py" "$out/iv0.0199" "$out/iv0.02" "$out/iv0.01"
