#!/bin/sh
# A stand-in for the soupuv CLI that speaks its worker protocol, for testing the
# server's process supervision only (timeouts, crashes, cancel, queue limits):
# it never maps anything, and no test takes its output as a mapping result.
# Behaviour comes from SOUPUV_TEST_WORKER_MODE in the server's environment:
#   slow  - progress for SOUPUV_TEST_WORKER_SECONDS (default 30) then copy input
#   crash - killed by SIGSEGV      hang - ignores SIGTERM, sleeps
#   fail  - "soupuv: ..." and exit 3 (invalid input)
#   badprogress - a progress line whose fraction is not a number, then as slow
#   stamp - as slow, but the result (and diagnostics) also carry this run's pid
#           and clock, so two runs of one job store different bytes: a test
#           can tell whose result a download serves (never a mapping)
#   escape - what a hostile model's parser would try: read the files named by
#            SOUPUV_TEST_ESCAPE_READ (colon-separated) and the server's
#            environment, write SOUPUV_TEST_ESCAPE_WRITE, print its
#            capabilities and environment, flood stdout (8 MB); reports each
#            attempt on stderr
case "$1" in
  --help) echo "usage: soupuv map IN -o OUT --diagnostics D --progress json --method M --texture-size N; soupuv inspect IN"; exit 0 ;;
  capabilities) echo '{"commands":["inspect","map","capabilities"],"map_flags":["-o","--diagnostics","--progress","--method","--texture-size"]}'; exit 0 ;;
  inspect) echo '{"triangles":1}'; exit 0 ;;
  map) [ "$2" = "--help" ] && exit 0 ;;
  *) echo "soupuv: unknown command" >&2; exit 2 ;;
esac
shift
in="$1"; shift
out=""; diag=""
while [ $# -gt 0 ]; do
  case "$1" in
    -o) out="$2"; shift ;;
    --diagnostics) diag="$2"; shift ;;
  esac
  shift
done
mode="${SOUPUV_TEST_WORKER_MODE:-slow}"
secs="${SOUPUV_TEST_WORKER_SECONDS:-30}"
case "$mode" in
  escape)
    IFS=:
    for f in $SOUPUV_TEST_ESCAPE_READ /proc/$PPID/environ; do
      if cat "$f" >&2 2>/dev/null; then echo "escape: read $f" >&2; else echo "escape: denied read $f" >&2; fi
    done
    unset IFS
    if echo escaped > "$SOUPUV_TEST_ESCAPE_WRITE" 2>/dev/null; then echo "escape: wrote outside" >&2
    else echo "escape: denied write" >&2; fi
    # Its capabilities, read by the shell itself (its own /proc entry).
    while read -r line; do case "$line" in CapEff:*|CapBnd:*) echo "escape: $line" >&2 ;; esac; done < /proc/self/status
    echo "escape: environment follows" >&2
    env >&2
    yes | head -c 8000000
    echo "soupuv: escape double finished" >&2
    exit 3 ;;
  crash) kill -SEGV $$ ;;
  fail) echo "soupuv: test double refuses this input" >&2; exit 3 ;;
  hang) trap '' TERM; while :; do sleep 1; done ;;
esac
trap 'exit 130' TERM
[ "$mode" = badprogress ] && echo '{"stage":"wait","fraction":"half"}' >&2
i=0
while [ "$i" -lt "$secs" ]; do
  echo "{\"stage\":\"wait\",\"fraction\":0.$i}" >&2
  sleep 1 &
  wait $!
  i=$((i + 1))
done
cp "$in" "$out"
run="$$-$(date +%s%N)"
[ "$mode" = stamp ] && echo "run $run" >> "$out"
if [ -n "$diag" ]; then
  if [ "$mode" = stamp ]; then echo "{\"double\":true,\"run\":\"$run\"}" > "$diag"
  else echo '{"double":true}' > "$diag"; fi
fi
exit 0
