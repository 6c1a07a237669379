#!/bin/sh
# Runs a solver into OUT, then a checker on OUT.
# usage: run_and_check.sh OUT CHECKER [CHECKER_ARGS...] -- SOLVER [SOLVER_ARGS...]
# The solver gets "--out OUT --quiet" appended; the checker gets OUT first.
# Exit status: the solver's if it failed before writing a summary, else the
# checker's (the checkers also report a solver that stopped early).
out=$1; shift
checker=$1; shift
cargs=""
while [ $# -gt 0 ] && [ "$1" != "--" ]; do cargs="$cargs $1"; shift; done
[ "$1" = "--" ] && shift
rm -rf "$out"
"$@" --out "$out" --quiet
rc=$?
if [ ! -f "$out/summary.json" ]; then
    echo "run_and_check: the solver wrote no summary (exit $rc)"
    exit 1
fi
# shellcheck disable=SC2086
/usr/bin/python3 "$checker" "$out" $cargs
