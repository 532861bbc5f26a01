#!/usr/bin/env bash
# cli.map.* — maps one sample and checks everything the output promises:
#   map exits 0; the GLB passes the Khronos validator with 0 errors and has
#   TEXCOORD_0 + an embedded baseColorTexture everywhere; the diagnostics match
#   proto/diagnostics.schema.json; and our own loader reads the output back with
#   as many triangles as the input had (for --draco this decodes every payload).
# usage: map_and_validate.sh SOUPUV SOURCE_DIR INPUT OUTBASE [map flags...]
set -euo pipefail
soupuv=$1 source_dir=$2 input=$3 out=$4
shift 4
mkdir -p "$(dirname "$out")"
rm -f "$out.glb" "$out.json"

"$soupuv" map "$input" -o "$out.glb" --diagnostics "$out.json" --progress none "$@" >/dev/null
node "$source_dir/tests/tools/validate.mjs" "$out.glb" --soupuv-output --quiet
node "$source_dir/tests/tools/check_schema.mjs" "$source_dir/proto/diagnostics.schema.json" "$out.json"

# inspect pretty-prints with two-space indentation: the top-level count is the
# line '  "triangles": N,'.
triangles() { "$soupuv" inspect "$@" | sed -n 's/^  "triangles": \([0-9]*\),\{0,1\}$/\1/p'; }
before=$(triangles "$input")
after=$(triangles "$out.glb")
if [ -z "$before" ] || [ "$before" != "$after" ]; then
  echo "triangle count changed: input $before, output $after"
  exit 1
fi
echo "round trip: $after triangles"
