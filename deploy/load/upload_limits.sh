#!/usr/bin/env bash
# Upload limits of soupuv-server with curl (loopback or your own deployment):
#  1. a valid 50 MB GLB (the shared Box.glb with its buffer padded) is
#     accepted; with -p PID the server's peak RSS growth is printed (it must
#     stay far below 50 MB: uploads stream to disk);
#  2. a 1 GB upload (sparse file, streamed by curl -T) is refused with 413
#     before it is read: bytes curl managed to send are printed, with and
#     without Expect: 100-continue.
#   deploy/load/upload_limits.sh [-u URL] [-p SERVER_PID]
set -euo pipefail
url=http://127.0.0.1:8080 pid=""
here=$(cd "$(dirname "$0")" && pwd)
while getopts "u:p:" o; do case $o in u) url=$OPTARG ;; p) pid=$OPTARG ;; *) exit 2 ;; esac; done
auth=()
[ -n "${SOUPUV_TOKEN:-}" ] && auth=(-H "Authorization: Bearer $SOUPUV_TOKEN")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
hwm() { [ -n "$pid" ] && awk '/VmHWM/ {print $2}' "/proc/$pid/status" || echo 0; }

python3 - "$here/../../../shared/data/gltf/Box.glb" "$tmp/big.glb" <<'PY'
import json, struct, sys
src = open(sys.argv[1], "rb").read()
jlen = struct.unpack_from("<I", src, 12)[0]
doc = json.loads(src[20:20 + jlen])
blen = struct.unpack_from("<I", src, 20 + jlen)[0]
bin_ = src[28 + jlen:28 + jlen + blen] + bytes(50 * 2**20 - blen)
doc["buffers"][0]["byteLength"] = len(bin_)
js = json.dumps(doc).encode()
js += b" " * (-len(js) % 4)
out = b"glTF" + struct.pack("<II", 2, 12 + 8 + len(js) + 8 + len(bin_))
out += struct.pack("<I", len(js)) + b"JSON" + js + struct.pack("<I", len(bin_)) + b"BIN\0" + bin_
open(sys.argv[2], "wb").write(out)
PY
before=$(hwm)
r=$(curl -sS -o "$tmp/r50" -w '%{http_code} %{time_total} %{size_upload}' "${auth[@]}" -X POST \
  -H 'Content-Type: model/gltf-binary' -T "$tmp/big.glb" "$url/v1/jobs?method=box&texture_size=64")
after=$(hwm)
read -r code t sent <<<"$r"
echo "50 MB upload: HTTP $code in ${t}s, $sent bytes sent$( [ -n "$pid" ] && echo ", server peak RSS grew $(( (after - before) / 1024 )) MB")"
[ "$code" = 202 ] || { cat "$tmp/r50"; exit 1; }

truncate -s 1G "$tmp/huge.glb"
for expect in "Expect: 100-continue" "Expect:"; do
  r=$(curl -sS -o "$tmp/r1g" -w '%{http_code} %{time_total} %{size_upload}' "${auth[@]}" -X POST -H "$expect" \
    -H 'Content-Type: model/gltf-binary' -T "$tmp/huge.glb" "$url/v1/jobs" 2>/dev/null) || true
  read -r code t sent <<<"$r"
  echo "1 GB upload ($expect): HTTP $code in ${t}s after $sent of 1073741824 bytes"
  [ "$code" = 413 ] || exit 1
done
echo "upload limits OK"
