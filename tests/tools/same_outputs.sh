#!/usr/bin/env bash
# Shows that a change left the pipeline's outputs alone: maps shared samples
# with an old and a new soupuv binary and compares the GLBs byte for byte
# (field method, the default, and box), then maps them again with the new
# binary through a cache directory, twice (a cold and a warm cache), and
# compares those with the uncached map too (cache keys never change outputs).
#
# usage: tests/tools/same_outputs.sh OLD NEW [SAMPLE.glb ...]
#   OLD, NEW  soupuv binaries, or a git revision for OLD (built here, release,
#             into build/same-outputs-REV from `git archive REV`)
#   SAMPLE    default: suzanne, spot and teapot from ../shared/data/soups
# Exit 0 when every pair is identical; prints one line per comparison.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
old=$1 new=$2
shift 2
samples=("$@")
if [ ${#samples[@]} -eq 0 ]; then
  for s in suzanne spot teapot; do samples+=("$root/../shared/data/soups/$s-soup.glb"); done
fi

if [ ! -x "$old" ]; then  # a revision: build its soupuv
  rev=$(git -C "$root" rev-parse --short "$old")
  tree="$root/build/same-outputs-$rev"
  if [ ! -x "$tree/build/core/apps/soupuv" ]; then
    mkdir -p "$tree/src"
    git -C "$root" archive "$rev" | tar -x -C "$tree/src"
    CCACHE_BASEDIR="$tree/src" CCACHE_NOHASHDIR=1 cmake -S "$tree/src" -B "$tree/build" -G Ninja \
      -DCMAKE_BUILD_TYPE=Release -DSOUPUV_BUILD_TESTS=OFF -DSOUPUV_BUILD_SERVER=OFF >/dev/null
    CCACHE_BASEDIR="$tree/src" CCACHE_NOHASHDIR=1 cmake --build "$tree/build" --target soupuv -j "${SOUPUV_JOBS:-2}"
  fi
  old="$tree/build/core/apps/soupuv"
fi

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
failed=0
same() {  # same LABEL A B
  if cmp -s "$2" "$3"; then echo "same      $1"; else echo "DIFFERENT $1"; failed=1; fi
}
for sample in "${samples[@]}"; do
  name=$(basename "$sample" .glb)
  for method in field box; do
    "$old" map "$sample" -o "$out/$name.$method.old.glb" --method "$method" --progress none >/dev/null
    "$new" map "$sample" -o "$out/$name.$method.new.glb" --method "$method" --progress none >/dev/null
    same "$name --method $method: old vs new" "$out/$name.$method.old.glb" "$out/$name.$method.new.glb"
  done
  for run in cold warm; do
    "$new" map "$sample" -o "$out/$name.$run.glb" --cache-dir "$out/cache" --progress none \
      --diagnostics "$out/$name.$run.json" >/dev/null
    same "$name --cache-dir ($run cache) vs no cache" "$out/$name.field.new.glb" "$out/$name.$run.glb"
  done
  # The warm run must have read its field lines from the cache.
  if ! /usr/bin/python3 -c 'import json, sys; sys.exit(not json.load(open(sys.argv[1]))["stages"]["field_cache"])' \
       "$out/$name.warm.json" 2>/dev/null; then
    echo "NO HIT    $name: the warm run did not read the cache"; failed=1
  fi
done
exit $failed
