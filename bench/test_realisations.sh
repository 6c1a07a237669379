#!/bin/sh
# Runs one ctest test as ctest would, from jittered starts: every solver
# command of the test gets --set fluid.jitter.amplitude=0.001 --set
# fluid.jitter.seed=K (inserted after each --quiet; a test of two runs gets
# the same start in both), one seed after another, one thread. Each seed's
# output goes to OUT/TEST_sK.log; the last lines are printed. It tells how
# far a validation band sits from the spread of realisations, which a single
# run of the lattice cannot (docs/testing.md, "The coupled tests' bands
# against four realisations").
# usage: bench/test_realisations.sh BUILD_DIR OUT_DIR TEST SEED...   (from the repository root)
build=$1; out=$2; t=$3; shift 3
mkdir -p "$out" || exit 1
cmd=$(cd "$build" && ctest -N -V -R "^$t\$" | grep 'Test command' |
      sed 's/^[0-9]*: Test command: \/usr\/bin\/sh "-c" "//; s/"$//')
[ -n "$cmd" ] || { echo "test_realisations: no test $t in $build" >&2; exit 2; }
case "$cmd" in *" --quiet "*) ;; *) echo "test_realisations: $t has no solver command with --quiet" >&2; exit 2;; esac
for s in "$@"; do
    c=$(echo "$cmd" | sed "s| --quiet | --quiet --set fluid.jitter.amplitude=0.001 --set fluid.jitter.seed=$s |g")
    echo "== $t seed $s"
    OMP_NUM_THREADS=1 sh -c "$c" > "$out/${t}_s$s.log" 2>&1
    echo "exit $?"
    tail -6 "$out/${t}_s$s.log"
done
