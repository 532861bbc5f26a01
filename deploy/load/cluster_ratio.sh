#!/usr/bin/env bash
# Does distribution cost anything? On one machine, 3 soupuv-server nodes x 1
# worker against 1 node x 3 workers, both on the same PostgreSQL
# (--database-url), the same batch of jobs, in the same run (A B B A, so a
# drift in the machine's load falls on both). Prints each run's wall time
# (first upload to last job succeeded) and the ratio; PASS when 3x1 is within
# 15 % of 1x3. Loopback only; starts its own PostgreSQL in a temp directory
# (as the `postgres` user when run as root).
#   deploy/load/cluster_ratio.sh [-n JOBS] [-f FILE] [-m METHOD] [-s SERVER_BIN]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
n=30 method=box
file=$here/../../../shared/data/soups/stanford-bunny-soup.glb
server=$here/../../build/release/server/soupuv-server
while getopts "n:f:m:s:" o; do
  case $o in n) n=$OPTARG ;; f) file=$OPTARG ;; m) method=$OPTARG ;; s) server=$OPTARG ;; *) exit 2 ;; esac
done
bin=$(ls -d /usr/lib/postgresql/*/bin | sort -V | tail -1)
work=$(mktemp -d /tmp/soupuv-ratio-XXXXXX)
mkdir -p "$work/pg" "$work/sock"
chmod 755 "$work"
as=()
# PostgreSQL refuses root: its directories belong to `postgres`; the nodes'
# data directories stay root's (a sandboxed worker, without capabilities,
# could not enter a directory of another user).
if [ "$(id -u)" = 0 ]; then chown postgres: "$work/pg" "$work/sock"; as=(runuser -u postgres --); fi
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  "${as[@]}" "$bin/pg_ctl" -D "$work/pg" -m immediate stop >/dev/null 2>&1 || true
  rm -rf "$work"
}
trap cleanup EXIT
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
"${as[@]}" "$bin/initdb" -D "$work/pg" -U soupuv --auth=trust -E UTF8 --locale=C >/dev/null
printf "listen_addresses='127.0.0.1'\nport=%s\nunix_socket_directories='%s'\n" "$port" "$work/sock" >> "$work/pg/postgresql.conf"
"${as[@]}" "$bin/pg_ctl" -D "$work/pg" -l "$work/sock/pg.log" -w start >/dev/null

run() {  # $1 = label, $2 = nodes, $3 = workers per node; prints seconds
  local label=$1 nodes=$2 workers=$3 db="r$RANDOM$RANDOM" urls=() i
  psql -q -h 127.0.0.1 -p "$port" -U soupuv -d postgres -c "CREATE DATABASE $db" >/dev/null
  pids=()
  for ((i = 0; i < nodes; i++)); do
    mkdir -p "$work/$db-$i"
    "$server" --port 0 --data-dir "$work/$db-$i" --database-url "postgresql://soupuv@127.0.0.1:$port/$db" \
      --workers "$workers" --threads "$workers" --queue-capacity 1000 2> "$work/$db-$i.log" &
    pids+=($!)
  done
  for ((i = 0; i < nodes; i++)); do
    local p=""
    for _ in $(seq 100); do
      p=$(sed -n 's/.*"msg":"listening","port":\([0-9]*\).*/\1/p' "$work/$db-$i.log" | head -1)
      [ -n "$p" ] && break
      sleep 0.1
    done
    [ -n "$p" ] || { echo "node $i did not start" >&2; cat "$work/$db-$i.log" >&2; exit 1; }
    urls+=("http://127.0.0.1:$p")
  done
  local t0 t1 k clients=()
  t0=$(date +%s.%N)
  # Three clients, spread over the nodes (round robin), as a balancer would.
  for ((k = 0; k < 3; k++)); do
    (for ((i = k; i < n; i += 3)); do
       body=$(curl -sS -H 'Content-Type: model/gltf-binary' --data-binary "@$file" \
         "${urls[$((i % nodes))]}/v1/jobs?method=$method")
       id=$(sed -n 's/.*"id":"\(j[a-z2-7]*\)".*/\1/p' <<< "$body")
       if [ -n "$id" ]; then echo "$id"; else echo "$label: refused: ${body:0:300}" >&2; fi
     done) > "$work/$db.ids.$k" &
    clients+=($!)
  done
  wait "${clients[@]}"
  cat "$work/$db".ids.* > "$work/$db.ids"
  [ "$(wc -l < "$work/$db.ids")" = "$n" ] || { echo "$label: only $(wc -l < "$work/$db.ids") of $n accepted" >&2; exit 1; }
  while :; do
    local left
    left=$(psql -qtA -h 127.0.0.1 -p "$port" -U soupuv -d "$db" \
      -c "SELECT COUNT(*) FROM soupuv_jobs WHERE state <> 'succeeded'")
    [ "$left" = 0 ] && break
    if [ "$(psql -qtA -h 127.0.0.1 -p "$port" -U soupuv -d "$db" -c "SELECT COUNT(*) FROM soupuv_jobs WHERE state IN ('failed','canceled')")" != 0 ]; then
      echo "$label: a job failed" >&2; exit 1
    fi
    sleep 0.1
  done
  t1=$(date +%s.%N)
  for p in "${pids[@]}"; do kill "$p"; done
  wait "${pids[@]}" 2>/dev/null || true
  pids=()
  python3 -c "print(f'{$t1 - $t0:.2f}')"
}

echo "batch: $n x $(basename "$file") method=$method; load average $(cut -d' ' -f1-3 /proc/loadavg)"
a1=$(run "1x3" 1 3); echo "1 node x 3 workers: $a1 s"
b1=$(run "3x1" 3 1); echo "3 nodes x 1 worker: $b1 s"
b2=$(run "3x1" 3 1); echo "3 nodes x 1 worker: $b2 s"
a2=$(run "1x3" 1 3); echo "1 node x 3 workers: $a2 s"
python3 - "$a1" "$a2" "$b1" "$b2" <<'PY'
import sys
a1, a2, b1, b2 = map(float, sys.argv[1:])
ratio = (b1 + b2) / (a1 + a2)
print(f"ratio (3x1)/(1x3) = {ratio:.3f}  ({'PASS' if ratio <= 1.15 else 'FAIL'}: target <= 1.15)")
PY
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
