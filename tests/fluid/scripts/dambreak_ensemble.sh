#!/bin/sh
# fluid_valid_dambreak's runs: the 8 mm dam break to T = 3.1 as the case has
# it (s0) and in N - 1 more realisations from lattices jittered by 1e-3 dp
# (s1 .. sN-1, the seed K; docs/fluid.md "Initial positions"), then
# check_dambreak.py on the N of them: its bands hold their means. One run's
# front speed is one draw from a spread of 3.1 points (sd over 16
# realisations, -3.1 to +8.4%, tests/fluid/validation.cmake): the mean of 8
# moves by 1.1.
# usage: dambreak_ensemble.sh SOLVER OUT_DIR N [check_dambreak.py options]
solver=$1; out=$2; n=$3; shift 3
rm -rf "$out"
mkdir -p "$out" || exit 1
runs=""
s=0
while [ "$s" -lt "$n" ]; do
    jitter=""
    [ "$s" -gt 0 ] && jitter="--set fluid.jitter.amplitude=0.001 --set fluid.jitter.seed=$s"
    "$solver" cases/dambreak/case.yml --out "$out/s$s" --quiet --set dp=0.008 \
        --set end_time=0.27 --set output.interval=0 $jitter || exit 1
    runs="$runs $out/s$s"
    s=$((s + 1))
done
exec /usr/bin/python3 "$(dirname "$0")/../check_dambreak.py" $runs "$@"
