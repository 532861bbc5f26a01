#!/usr/bin/env bash
# cli.cancel — SIGTERM during a run stops it through the Progress cancel token:
# exit code 130 from a normal exit, and no output file (written atomically).
# usage: cancel.sh SOUPUV INPUT OUTDIR
set -uo pipefail
soupuv=$1 input=$2 outdir=$3
mkdir -p "$outdir"
out="$outdir/canceled.glb" err="$outdir/canceled.stderr"
rm -f "$out" "$err"
"$soupuv" map "$input" -o "$out" --progress json 2>"$err" >/dev/null &
pid=$!
# The handlers are installed before the first progress line; wait for it.
for _ in $(seq 1 500); do
  grep -q '"stage"' "$err" 2>/dev/null && break
  sleep 0.01
done
kill -TERM "$pid"
wait "$pid"
rc=$?
cat "$err"
echo "exit code $rc"
if [ "$rc" -ne 130 ]; then echo "FAIL: expected 130"; exit 1; fi
if [ -e "$out" ]; then echo "FAIL: output written despite cancel"; exit 1; fi
tail -n 1 "$err" | grep -q '^soupuv: canceled' || { echo "FAIL: last line is not 'soupuv: canceled'"; exit 1; }
