#!/bin/sh
# expect_fail.sh PATTERN COMMAND [ARG]...
# Passes when COMMAND exits non-zero (and not by a signal) and its stderr is
# exactly one line matching the extended regular expression PATTERN.
pattern=$1
shift
err=$(mktemp) || exit 1
"$@" >/dev/null 2>"$err"
rc=$?
lines=$(wc -l <"$err")
msg=$(cat "$err")
rm -f "$err"
if [ "$rc" -eq 0 ]; then
    echo "FAIL: exit status 0, expected an error: $*"
    exit 1
fi
if [ "$rc" -gt 128 ]; then
    echo "FAIL: killed by signal $((rc - 128)): $*"
    exit 1
fi
if [ "$lines" -ne 1 ]; then
    echo "FAIL: expected one line on stderr, got $lines:"
    echo "$msg"
    exit 1
fi
if ! printf '%s\n' "$msg" | grep -Eq -- "$pattern"; then
    echo "FAIL: stderr does not match /$pattern/:"
    echo "$msg"
    exit 1
fi
echo "ok (exit $rc): $msg"
