#!/usr/bin/env bash
# Load test of soupuv-server with curl (loopback or your own deployment only).
#   deploy/load/load.sh [-u URL] [-n JOBS] [-c CONCURRENCY] [-f FILE] [-m METHOD] [-q QUERY] [-t SECONDS]
# QUERY is extra job parameters (default texture_size=64: the load is on the
# server, not on PNG encoding).
# Submits N jobs from C concurrent clients (each retries 429/503 after
# Retry-After, at most 120 times), then polls each accepted job to its end,
# downloads and checks every result, while a prober measures GET /v1/jobs/{id}
# and /healthz latency.
# Prints throughput, latency percentiles, counts by HTTP status, and checks:
# no 5xx, every 429/503 had Retry-After, no lost or duplicated job.
# Bounded: stops after -t seconds (default 600) whatever happens.
set -uo pipefail
url=http://127.0.0.1:8080 n=20 c=4 method=box limit=600 query=texture_size=64
here=$(cd "$(dirname "$0")" && pwd)
file=$here/../../../shared/data/gltf/Box.glb
while getopts "u:n:c:f:m:q:t:" o; do
  case $o in u) url=$OPTARG ;; n) n=$OPTARG ;; c) c=$OPTARG ;; f) file=$OPTARG ;; m) method=$OPTARG ;; q) query=$OPTARG ;;
    t) limit=$OPTARG ;; *) exit 2 ;; esac
done
auth=()
[ -n "${SOUPUV_TOKEN:-}" ] && auth=(-H "Authorization: Bearer $SOUPUV_TOKEN")
case "$file" in *.gltf) type=model/gltf+json ;; *.drc) type=application/octet-stream ;; *) type=model/gltf-binary ;; esac
work=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null; rm -rf "$work"' EXIT
deadline=$(( $(date +%s) + limit ))
export url file type method work deadline query
export auth_header=${SOUPUV_TOKEN:+"Authorization: Bearer $SOUPUV_TOKEN"}

submit_one() {  # $1 = job number; appends to $work/submits and $work/ids
  local i=$1 code t tries=0 h=()
  [ -n "$auth_header" ] && h=(-H "$auth_header")
  while :; do
    tries=$((tries + 1))
    out=$(curl -sS -D "$work/h.$i" -o "$work/b.$i" -w '%{http_code} %{time_total}' "${h[@]}" \
      -H "Content-Type: $type" -H "Idempotency-Key: load-$$-$i" --data-binary "@$file" "$url/v1/jobs?method=$method${query:+&$query}") || out="000 0"
    read -r code t <<<"$out"
    ra=$(grep -i '^Retry-After:' "$work/h.$i" | tr -dc '0-9')
    echo "$code $t ${ra:-none}" >> "$work/submits"
    if [ "$code" = 429 ] || [ "$code" = 503 ]; then
      [ $tries -ge 120 ] || [ "$(date +%s)" -ge "$deadline" ] && break
      sleep "${ra:-1}"
      continue
    fi
    break
  done
  if [ "$code" = 202 ]; then
    # The server's JSON is compact; sed is enough and far cheaper than a python per job.
    echo "$i $(sed -n 's/.*"id":"\(j[a-z2-7]*\)".*/\1/p' "$work/b.$i")" >> "$work/ids"
  else
    echo "$i none not-accepted" >> "$work/jobs"
  fi
}
export -f submit_one

check_one() {  # $1 = "number id": polls to the end, downloads and checks the GLB
  local i=${1%% *} id=${1#* } state=lost h=()
  [ -n "$auth_header" ] && h=(-H "$auth_header")
  while [ "$(date +%s)" -lt "$deadline" ]; do
    state=$(curl -sS "${h[@]}" "$url/v1/jobs/$id" | sed -n 's/.*"state":"\([a-z]*\)".*/\1/p')
    case "$state" in succeeded|failed|canceled) break ;; esac
    sleep 1  # many clients on few cores: polling must not starve the workers
  done
  if [ "$state" = succeeded ]; then
    curl -sS -f "${h[@]}" -o "$work/r.$i" "$url/v1/jobs/$id/result" && [ "$(head -c 4 "$work/r.$i")" = glTF ] || state=bad-result
    rm -f "$work/r.$i"
  fi
  echo "$i $id $state" >> "$work/jobs"
}
export -f check_one

probe() {  # status/health latency while the jobs run: one curl per 20 requests
  # on a kept-alive connection, so process start-up is not in the numbers.
  local h=() urls
  [ -n "$auth_header" ] && h=(-H "$auth_header")
  while [ ! -f "$work/done" ] && [ "$(date +%s)" -lt "$deadline" ]; do
    id=$(tail -n 1 "$work/ids" 2>/dev/null | cut -d' ' -f2)
    if [ -n "$id" ]; then
      urls=$(for _ in $(seq 10); do printf '%s ' "$url/v1/jobs/$id"; done)
      # shellcheck disable=SC2086
      curl -sS -o /dev/null -w '%{http_code} %{time_total}\n' "${h[@]}" $urls >> "$work/status"
    fi
    urls=$(for _ in $(seq 10); do printf '%s ' "$url/healthz"; done)
    # shellcheck disable=SC2086
    curl -sS -o /dev/null -w '%{http_code} %{time_total}\n' $urls >> "$work/health"
    sleep 0.2
  done
}

touch "$work/submits" "$work/jobs" "$work/ids" "$work/status" "$work/health"
probe &
start=$(date +%s.%N)
# Open loop: every client submits as fast as it is let (so the queue fills and
# 429 + Retry-After happen), then every accepted job is followed to its end.
seq 1 "$n" | xargs -P "$c" -I{} bash -c 'submit_one {}'
xargs -P "$c" -I{} bash -c 'check_one "{}"' < "$work/ids"
end=$(date +%s.%N)
touch "$work/done"
wait

# percentiles of column 2 (seconds), printed in ms
pct() {
  awk '{print $2}' "$1" | sort -n | awk '{a[NR]=$1} END {
    if (NR == 0) { print "n=0"; exit }
    i50 = int(NR * 0.50); if (i50 < 1) i50 = 1
    i95 = int(NR * 0.95); if (i95 < 1) i95 = 1
    i99 = int(NR * 0.99); if (i99 < 1) i99 = 1
    printf "n=%d p50=%.1fms p95=%.1fms p99=%.1fms max=%.1fms\n", NR, a[i50]*1000, a[i95]*1000, a[i99]*1000, a[NR]*1000 }'
}
secs=$(awk -v a="$start" -v b="$end" 'BEGIN {printf "%.2f", b - a}')
ok=$(awk '$3 == "succeeded"' "$work/jobs" | wc -l)
echo "jobs: $n submitted by $c clients in ${secs}s -> $(awk -v a="$ok" -v b="$secs" 'BEGIN {printf "%.2f", a / b}') succeeded jobs/s"
echo "final states: $(awk '{print $3}' "$work/jobs" | sort | uniq -c | tr '\n' ' ')"
echo "submit HTTP status counts: $(awk '{print $1}' "$work/submits" | sort | uniq -c | tr '\n' ' ')"
echo "submit latency:  $(pct "$work/submits")"
echo "status latency:  $(pct "$work/status")"
echo "healthz latency: $(pct "$work/health")"
fail=0
n5xx=$(awk '$1 ~ /^5/ && $1 != 503' "$work/submits" "$work/status" "$work/health" | wc -l)
[ "$n5xx" -eq 0 ] || { echo "CHECK FAILED: $n5xx responses were 5xx (other than 503)"; fail=1; }
noretry=$(awk '($1 == 429 || $1 == 503) && $3 == "none"' "$work/submits" | wc -l)
[ "$noretry" -eq 0 ] || { echo "CHECK FAILED: $noretry 429/503 without Retry-After"; fail=1; }
other=$(awk '$1 != 202 && $1 != 429 && $1 != 503' "$work/submits" | wc -l)
[ "$other" -eq 0 ] || { echo "CHECK FAILED: $other submissions answered neither 202 nor 429/503"; fail=1; }
dups=$(cut -d' ' -f2 "$work/ids" | sort | uniq -d | wc -l)
[ "$dups" -eq 0 ] || { echo "CHECK FAILED: $dups job ids handed out twice"; fail=1; }
[ "$ok" -eq "$n" ] || { echo "CHECK FAILED: $ok of $n jobs succeeded (lost or failed: see final states)"; fail=1; }
[ $fail -eq 0 ] && echo "load OK" || exit 1
