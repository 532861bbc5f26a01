#!/usr/bin/env bash
# Status and health latency while every worker is busy (issue 7 target: p99 < 10 ms).
#   deploy/load/status_latency.sh [-u URL] [-d SECONDS] [-p PROBERS] [-U UPLOADERS] [-f BUSY_FILE] [-F UPLOAD_FILE]
# 1. Makes every worker busy: submits one field job per worker (plus as many
#    again queued) on BUSY_FILE (default: the shared stanford-bunny soup) and
#    waits until /metrics shows workers_busy == workers.
# 2. For SECONDS (default 30) runs PROBERS (default 1) curl loops on each of
#    GET /v1/jobs/{id}, /healthz and /readyz, while UPLOADERS (default 2) loops
#    keep submitting UPLOAD_FILE (default Box.glb, method box) so uploads,
#    inspections and SQLite writes compete with the polls, as in production.
# 3. Cancels what it submitted and prints, per endpoint: n, p50, p90, p99, max
#    (curl time_total: connect + request + response; keep-alive is per request
#    here, so each sample includes a TCP connect on loopback) and a PASS/FAIL
#    line against p99 < 10 ms for status and health.
# Needs a running soupuv-server (see server/README.md). Loopback only.
set -uo pipefail
url=http://127.0.0.1:8080 secs=30 probers=1 uploaders=2
here=$(cd "$(dirname "$0")" && pwd)
busy_file=$here/../../../shared/data/soups/stanford-bunny-soup.glb
upload_file=$here/../../../shared/data/gltf/Box.glb
while getopts "u:d:p:U:f:F:" o; do
  case $o in u) url=$OPTARG ;; d) secs=$OPTARG ;; p) probers=$OPTARG ;; U) uploaders=$OPTARG ;;
    f) busy_file=$OPTARG ;; F) upload_file=$OPTARG ;; *) exit 2 ;; esac
done
h=()
[ -n "${SOUPUV_TOKEN:-}" ] && h=(-H "Authorization: Bearer $SOUPUV_TOKEN")
work=$(mktemp -d)
submitted=()
cleanup() {
  kill $(jobs -p) 2>/dev/null
  # Cancel what still runs, then delete (a job still stopping answers 409
  # to DELETE and goes with its TTL).
  for id in "${submitted[@]}" $(cat "$work/uploaded" 2>/dev/null); do
    curl -sS -o /dev/null "${h[@]}" -X POST "$url/v1/jobs/$id:cancel" || true
  done
  sleep 1
  for id in "${submitted[@]}" $(cat "$work/uploaded" 2>/dev/null); do
    curl -sS -o /dev/null "${h[@]}" -X DELETE "$url/v1/jobs/$id" || true
  done
  rm -rf "$work"
}
trap cleanup EXIT

metric() { curl -sS "${h[@]}" "$url/metrics" | awk -v n="soupuv_$1" '$1 == n {print int($2)}'; }
workers=$(metric workers)
[ -n "$workers" ] || { echo "no soupuv-server at $url" >&2; exit 1; }

# 1. every worker busy (field method on a large soup: minutes of work each)
for _ in $(seq 1 $((2 * workers))); do
  id=$(curl -sS "${h[@]}" -H 'Content-Type: model/gltf-binary' --data-binary "@$busy_file" \
    "$url/v1/jobs?method=field" | sed -n 's/.*"id":"\(j[a-z2-7]*\)".*/\1/p')
  [ -n "$id" ] && submitted+=("$id")
done
[ ${#submitted[@]} -gt 0 ] || { echo "could not submit the busy jobs" >&2; exit 1; }
for _ in $(seq 1 120); do
  [ "$(metric workers_busy)" = "$workers" ] && break
  sleep 0.5
done
[ "$(metric workers_busy)" = "$workers" ] || { echo "workers never all busy" >&2; exit 1; }
echo "workers busy: $workers of $workers; probing for ${secs}s with $probers probers and $uploaders uploaders"

# 2. probes (10 URLs per curl process, so process start-up is not in the numbers)
status_url="$url/v1/jobs/${submitted[0]}"
end=$(( $(date +%s) + secs ))
probe() {  # $1 = endpoint name, $2 = URL
  local args=()
  for _ in $(seq 10); do args+=(-o /dev/null "$2"); done  # -o applies to one URL each
  while [ "$(date +%s)" -lt "$end" ]; do
    curl -sS -w "$1 %{http_code} %{time_total}\n" "${h[@]}" "${args[@]}" >> "$work/samples.$BASHPID"
    sleep 0.05
  done
}
upload() {
  local code
  while [ "$(date +%s)" -lt "$end" ]; do
    code=$(curl -sS -o "$work/up.$BASHPID" -w '%{http_code}' "${h[@]}" -H 'Content-Type: model/gltf-binary' \
      --data-binary "@$upload_file" "$url/v1/jobs?method=box&texture_size=64")
    echo "$code" >> "$work/upload_codes"
    sed -n 's/.*"id":"\(j[a-z2-7]*\)".*/\1/p' "$work/up.$BASHPID" 2>/dev/null >> "$work/uploaded"
    [ "$code" = 202 ] || sleep 0.5  # queue full or uploads busy: back off as a client would
  done
}
curl -sS "${h[@]}" "$url/metrics" > "$work/metrics.before"
for _ in $(seq 1 "$probers"); do
  probe status "$status_url" & probe healthz "$url/healthz" & probe readyz "$url/readyz" &
done
for _ in $(seq 1 "$uploaders"); do upload & done
wait
busy_after=$(metric workers_busy)
curl -sS "${h[@]}" "$url/metrics" > "$work/metrics.after"

# 3. report
cat "$work"/samples.* > "$work/all"
report() {
  awk -v e="$1" '$1 == e {print $3}' "$work/all" | sort -n | awk -v e="$1" '{a[NR]=$1} END {
    if (NR == 0) { printf "%-8s n=0\n", e; exit }
    p = "p50 p90 p99"; split("0.50 0.90 0.99", q, " ")
    printf "%-8s n=%d", e, NR
    for (k = 1; k <= 3; k++) { i = int(NR * q[k] + 0.5); if (i < 1) i = 1; if (i > NR) i = NR; printf " p%d=%.2fms", q[k] * 100, a[i] * 1000 }
    printf " max=%.2fms\n", a[NR] * 1000 }'
}
for e in status healthz readyz; do report $e; done
# Inside the server (soupuv_http_request_duration_seconds, headers read to
# response written), over the probe window: if these are small while the
# client's tail is long, the tail is waiting for a CPU, not the server's work.
server_side() {  # $1 = route class
  awk -v r="route=\"$1\"" '
    FNR == 1 { f++ }
    index($0, "soupuv_http_request_duration_seconds_bucket{" r ",") == 1 {
      le = $0; sub(/.*le="/, "", le); sub(/".*/, "", le)
      if (f == 1) before[le] = $2; else { after[le] = $2; order[++n] = le } }
    END {
      total = after["+Inf"] - before["+Inf"]
      if (total <= 0) { printf "%-8s server-side: no samples\n", substr(r, 8, length(r) - 8); exit }
      p99 = "?"; under1 = 0; under10 = 0
      for (i = 1; i <= n; i++) {
        c = after[order[i]] - before[order[i]]
        if (order[i] == "0.001") under1 = c
        if (order[i] == "0.01") under10 = c
        if (p99 == "?" && c >= 0.99 * total) p99 = order[i]
      }
      printf "%-8s server-side: n=%d, %.1f%% <= 1 ms, %.1f%% <= 10 ms, p99 <= %s s\n", substr(r, 8, length(r) - 8), total, 100 * under1 / total, 100 * under10 / total, p99 }
  ' "$work/metrics.before" "$work/metrics.after"
}
for e in status healthz readyz; do server_side $e; done
echo "status codes: $(awk '{print $1 "=" $2}' "$work/all" | sort | uniq -c | tr '\n' ' ')"
echo "uploads during the probe, by HTTP status: $(sort "$work/upload_codes" 2>/dev/null | uniq -c | tr '\n' ' ')"
echo "workers busy at the end: $busy_after of $workers"
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
fail=0
for e in status healthz; do
  p99=$(awk -v e=$e '$1 == e {print $3}' "$work/all" | sort -n | awk '{a[NR]=$1} END {i=int(NR*0.99+0.5); if(i<1)i=1; print a[i]*1000}')
  awk -v p="$p99" 'BEGIN {exit !(p < 10)}' || { echo "FAIL: $e p99 ${p99} ms >= 10 ms"; fail=1; }
done
bad=$(awk '$2 != 200' "$work/all" | wc -l)
touch "$work/upload_codes"
[ "$bad" -eq 0 ] || { echo "FAIL: $bad probe responses were not 200"; fail=1; }
[ $fail -eq 0 ] && echo "PASS: status and health p99 < 10 ms with every worker busy"
exit $fail
