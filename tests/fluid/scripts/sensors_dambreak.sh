#!/bin/sh
# The 8 mm dam break to 0.35 s, its probes every 2 ms and every 10 ms: the
# right-wall sensor (cases/dambreak, p_wall) must see the impact when
# the front reaches the wall, and the 10 ms rows of the sensor and the wall
# force must be the time means of the 2 ms rows (check_sensors.py).
# h_wall: the height of the water in the column next to the right wall.
# usage: sensors_dambreak.sh SOLVER OUT_DIR
solver=$1; out=$2
rm -rf "$out"
for iv in 0.002 0.01; do
    "$solver" cases/dambreak/case.yml --out "$out/iv$iv" --quiet --set dp=0.008 \
        --set end_time=0.35 --set output.interval=0 --set output.probe_interval=$iv \
        --set fluid.probes.6.name=h_wall --set fluid.probes.6.kind=height \
        --set fluid.probes.6.x=0.576 || exit 1
done
check="/usr/bin/python3 $(dirname "$0")/../check_sensors.py"
$check "$out/iv0.002" --check dambreak --dp 0.008 || exit 1
exec $check "$out/iv0.002" --check means --coarse "$out/iv0.01" --columns p_wall,force_right
