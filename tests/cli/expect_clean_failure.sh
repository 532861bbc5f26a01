#!/usr/bin/env bash
# cli.bad.* / cli.usage.* — a command that must fail cleanly: non-zero exit
# code from a normal exit (not a signal, not a sanitizer abort) and exactly one
# line "soupuv: <reason>" on stderr.
# usage: expect_clean_failure.sh [--message REGEX] EXPECTED_CODE|any SOUPUV ARGS...
set -uo pipefail
message=""
if [ "$1" = --message ]; then message=$2; shift 2; fi
expected=$1
shift
err=$(mktemp)
trap 'rm -f "$err"' EXIT
"$@" >/dev/null 2>"$err"
rc=$?
lines=$(wc -l <"$err")
echo "exit code $rc; stderr:"
cat "$err"
if [ "$rc" -eq 0 ]; then echo "FAIL: succeeded"; exit 1; fi
if [ "$rc" -gt 125 ]; then echo "FAIL: killed by a signal or aborted (code $rc)"; exit 1; fi
if [ "$expected" != any ] && [ "$rc" -ne "$expected" ]; then echo "FAIL: expected exit code $expected"; exit 1; fi
if [ "$lines" -ne 1 ] || ! grep -q '^soupuv: ' "$err"; then echo "FAIL: stderr is not one 'soupuv: ' line"; exit 1; fi
if [ -n "$message" ] && ! grep -Eq "$message" "$err"; then echo "FAIL: reason does not match /$message/"; exit 1; fi
exit 0
