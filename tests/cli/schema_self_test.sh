#!/usr/bin/env bash
# cli.diagnostics_schema_can_fail — the diagnostics of a real run validate
# against proto/diagnostics.schema.json, and the checker rejects the same
# document with any required field removed (so the schema tests can fail).
# usage: schema_self_test.sh SOUPUV SOURCE_DIR INPUT OUTDIR
set -euo pipefail
soupuv=$1 source_dir=$2 input=$3 outdir=$4
mkdir -p "$outdir"
"$soupuv" map "$input" -o "$outdir/out.glb" --diagnostics "$outdir/diagnostics.json" --progress none --method box >/dev/null
node "$source_dir/tests/tools/check_schema.mjs" "$source_dir/proto/diagnostics.schema.json" \
     "$outdir/diagnostics.json" --self-test
