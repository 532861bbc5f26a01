#!/usr/bin/env bash
# Bit-identity check for refactors that must not change behaviour (issue 23).
#
#   bench/bitident.sh [BIN] [--write-ref]
#     BIN          the soupuv CLI to check (default build/release/core/apps/soupuv)
#     --write-ref  record BIN's hashes as the reference (bench/bitident.ref)
#
# Maps a few small shared samples with `soupuv map` (field method, fixed
# thread count: the proxy branch's share depends on it) to GLB + diagnostics
# and compares, per sample, the SHA-256 of the GLB bytes and of the
# diagnostics with everything that is not a result taken out (seconds, cache
# and thread counts, version, file names, and the keys only the paths removed
# by issue 23 item 6 filled, constant on the default path). Exit
# status 0 when every hash matches the reference, 1 otherwise; one line per
# sample either way. The reference in bench/bitident.ref was written by the
# binary of the commit it names.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin=$here/build/release/core/apps/soupuv
write=0
for a in "$@"; do
  case $a in
    --write-ref) write=1 ;;
    *) bin=$a ;;
  esac
done
data=${SOUPUV_SHARED:-$here/../shared/data}
[ -d "$data" ] || data=/work/shared/data
ref=$here/bench/bitident.ref
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# name | input | extra flags
cases=(
  "suzanne|soups/suzanne-soup.glb|"
  "spot-draco|soups/spot-soup-draco.glb|"
  "ThreeMeshes|corpus/ThreeMeshes-soup.glb|"
  "lamp-draco|corpus/lamp-draco-soup.glb|"
  "suzanne-box|soups/suzanne-soup.glb|--method box"
)

# The diagnostics' results: timing, cache, threads and names dropped.
normalize() {
  python3 - "$1" <<'EOF'
import hashlib, json, sys
d = json.load(open(sys.argv[1]))
for k in ("stages", "cache", "threads", "soupuv_version", "input", "output", "seconds",
          "uv_repair", "island_relax"):
    d.pop(k, None)
# What only the removed opt-in paths filled (issue 23 item 6; constant on the
# default path): the repair's counts, the candidate search's gate, the
# cut-triangle probes, the gap-keeping proxy.
def drop(path, keys):
    x = d
    for p in path:
        x = x.get(p, {}) if isinstance(x, dict) else {}
    for k in keys:
        if isinstance(x, dict):
            x.pop(k, None)
drop(["uv"], ["repaired_vertices", "repaired_triangles"])
drop(["uv", "causes"], ["diverged_by_repair"])
drop(["uv", "stretch_tail"], ["repaired"])
for w in d.get("uv", {}).get("stretch_tail", {}).get("worst", []):
    w.pop("repaired", None)
drop(["atlas"], ["candidate_search"])
drop(["trace"], ["probe_lines"])
drop(["intersections"], ["probes", "corrected_triangles"])
drop(["transfer"], ["cut_triangles_corrected"])
drop(["proxy"], ["gap_narrowed_triangles", "gap_smallest_offset"])
# The UV solve's energy sums are OpenMP reductions: their last bits change
# from run to run of one binary (suzanne: 4.372365907657027 / ...0245), so
# they are left out, and every other number is compared to 12 digits.
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if "seconds" not in k and "energy" not in k}
    if isinstance(x, list):
        return [strip(v) for v in x]
    if isinstance(x, float):
        return float("%.12g" % x)
    return x
print(hashlib.sha256(json.dumps(strip(d), sort_keys=True).encode()).hexdigest())
EOF
}

status=0
lines=()
for c in "${cases[@]}"; do
  IFS='|' read -r name input flags <<<"$c"
  # shellcheck disable=SC2086
  "$bin" map "$data/$input" -o "$out/$name.glb" --diagnostics "$out/$name.json" \
    --threads 2 --progress none $flags >/dev/null 2>&1
  glb=$(sha256sum "$out/$name.glb" | cut -d' ' -f1)
  diag=$(normalize "$out/$name.json")
  lines+=("$name $glb $diag")
  if [ $write = 0 ]; then
    want=$(awk -v n="$name" '$1 == n {print $2 " " $3}' "$ref")
    glb_ok=same; diag_ok=same
    [ "$glb" = "${want%% *}" ] || { glb_ok=DIFFERS; status=1; }
    [ "$diag" = "${want##* }" ] || { diag_ok=DIFFERS; status=1; }
    echo "$name: glb $glb_ok, diagnostics $diag_ok"
  fi
done
if [ $write = 1 ]; then
  {
    echo "# bench/bitident.sh reference: sample, sha256 of the GLB, sha256 of the normalized diagnostics"
    echo "# written by $("$bin" --version 2>/dev/null | head -1) at commit $(git -C "$here" rev-parse --short HEAD)"
    printf '%s\n' "${lines[@]}"
  } >"$ref"
  cat "$ref"
fi
exit $status
