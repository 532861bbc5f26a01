#!/usr/bin/env bash
# cli.field.texture_size_packs — the field method packs its islands for the
# texture it writes: with --texture-size 256 the packing's scale (texels per
# UV unit, diagnostics uv_solve.pack.texels_per_uv) is a quarter of the
# default 1024's, so the islands' padding is counted in the written
# texture's texels (a pack for 1024 would leave a quarter of the padding at
# 256 and let a bake bleed across islands).
# usage: texture_size_packs.sh SOUPUV INPUT OUTDIR
set -euo pipefail
soupuv=$1 input=$2 out=$3
mkdir -p "$out"
"$soupuv" map "$input" -o "$out/default.glb" --diagnostics "$out/default.json" --progress none >/dev/null
"$soupuv" map "$input" -o "$out/256.glb" --diagnostics "$out/256.json" --progress none --texture-size 256 >/dev/null
scale() { node -e 'console.log(JSON.parse(require("fs").readFileSync(process.argv[1])).uv_solve.pack.texels_per_uv)' "$1"; }
a=$(scale "$out/default.json")
b=$(scale "$out/256.json")
echo "texels per UV unit: default $a, --texture-size 256 $b"
# A quarter within the packer's scale search (it stops within a few %).
awk -v a="$a" -v b="$b" 'BEGIN { r = b / a; exit !(r > 0.2 && r < 0.3) }' || {
  echo "the pack did not follow --texture-size (ratio $(awk -v a="$a" -v b="$b" 'BEGIN{print b/a}'))"
  exit 1
}
