#!/usr/bin/env bash
# One job through soupuv-server with curl: submit, poll, download, verify.
#   deploy/load/smoke.sh [URL] [FILE] [METHOD]
# URL defaults to http://127.0.0.1:8080, FILE to the shared Box.glb, METHOD to box.
# SOUPUV_TOKEN, if set, is sent as a bearer token.
set -euo pipefail
url=${1:-http://127.0.0.1:8080}
here=$(cd "$(dirname "$0")" && pwd)
file=${2:-$here/../../../shared/data/gltf/Box.glb}
method=${3:-box}
auth=()
[ -n "${SOUPUV_TOKEN:-}" ] && auth=(-H "Authorization: Bearer $SOUPUV_TOKEN")
case "$file" in
  *.gltf) type=model/gltf+json ;;
  *.drc) type=application/octet-stream ;;
  *) type=model/gltf-binary ;;
esac
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# An explicit Content-Type: curl's default form encoding would hit httplib's limits.
code=$(curl -sS -o "$tmp/job.json" -w '%{http_code}' "${auth[@]}" -H "Content-Type: $type" \
  --data-binary "@$file" "$url/v1/jobs?method=$method")
[ "$code" = 202 ] || { echo "submit: HTTP $code: $(cat "$tmp/job.json")" >&2; exit 1; }
id=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["id"])' "$tmp/job.json")
echo "submitted $id"
state=queued
for _ in $(seq 1 600); do
  curl -sS "${auth[@]}" "$url/v1/jobs/$id" > "$tmp/job.json"
  state=$(python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); print(j["state"], j.get("stage", ""))' "$tmp/job.json")
  case "$state" in succeeded*|failed*|canceled*) break ;; esac
  sleep 0.2
done
echo "state: $state"
[ "${state%% *}" = succeeded ] || { cat "$tmp/job.json" >&2; exit 1; }
curl -sS -f "${auth[@]}" -o "$tmp/result.glb" "$url/v1/jobs/$id/result"
magic=$(head -c 4 "$tmp/result.glb")
[ "$magic" = glTF ] || { echo "result is not a GLB" >&2; exit 1; }
curl -sS -f "${auth[@]}" -o "$tmp/diag.json" "$url/v1/jobs/$id/diagnostics"
echo "result: $(stat -c %s "$tmp/result.glb") bytes GLB; diagnostics: $(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print("triangles", d.get("soup",{}).get("triangles"))' "$tmp/diag.json")"
echo "smoke OK"
