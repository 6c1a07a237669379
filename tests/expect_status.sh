#!/bin/sh
# expect_status.sh STATUS PATTERN COMMAND [ARG]...
# Passes when COMMAND exits with STATUS and some line of its stderr matches
# the extended regular expression PATTERN (for runs whose children write to
# stderr too, where expect_fail.sh's one-line rule cannot hold).
want=$1
pattern=$2
shift 2
err=$(mktemp) || exit 1
"$@" >/dev/null 2>"$err"
rc=$?
msg=$(cat "$err")
rm -f "$err"
if [ "$rc" -ne "$want" ]; then
    echo "FAIL: exit status $rc, expected $want: $*"
    echo "$msg"
    exit 1
fi
if ! printf '%s\n' "$msg" | grep -Eq -- "$pattern"; then
    echo "FAIL: stderr does not match /$pattern/:"
    echo "$msg"
    exit 1
fi
echo "ok (exit $rc): $(printf '%s\n' "$msg" | grep -E -- "$pattern" | head -1)"
