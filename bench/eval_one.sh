#!/usr/bin/env bash
# bench/eval_one.sh NAME [soupuv map flags...]
# Maps one corpus soup (../shared/data/corpus/NAME-soup.glb, or CORPUS=DIR)
# with build/release's soupuv and prints one line: the yardstick's figures
# (../shared/eval/uvmetrics.py against NAME-soup.ref.npz), the wall time, and
# the UV solve's step by step share of the weld's pairs kept (uv_solve.*
# .kept_pairs). The figures in docs/tuning.md come from this script.
# Needs /usr/bin/python3 with numpy and scipy (scripts/install-deps.sh).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
n=$1; shift
corpus=${CORPUS:-$here/../shared/data/corpus}
out=${OUT:-/tmp/soupuv-eval-one}; mkdir -p "$out"
t0=$(date +%s.%N)
"${SOUPUV:-$here/build/release/core/apps/soupuv}" map "$corpus/$n-soup.glb" -o "$out/$n.glb" --diagnostics "$out/$n.json" \
  --progress none "$@" >/dev/null 2>"$out/$n.err" || { echo "$n: map failed: $(tail -1 "$out/$n.err")"; exit 1; }
t1=$(date +%s.%N)
/usr/bin/python3 - "$n" "$out" "$corpus" "$t0" "$t1" "$here/../shared/eval/uvmetrics.py" <<'PY'
import json, subprocess, sys
n, out, corpus, t0, t1, metrics = sys.argv[1:7]
d = json.load(open(f"{out}/{n}.json"))
m = json.loads(subprocess.run(["/usr/bin/python3", metrics, f"{corpus}/{n}-soup.ref.npz", f"{out}/{n}.glb", "--json"],
                              capture_output=True, text=True, check=True).stdout.splitlines()[-1])
u = d.get("uv_solve", {})
kept = " ".join(f"{k}={u[k]['kept_pairs']:.3f}" for k in ("uv_mesh", "reembed_folds", "fold_cut", "reembed_overlaps", "overlap_split", "union_merge", "seam_merge") if k in u)
print(f"{n:24s} tris {d['soup']['triangles']:6d} wall {float(t1) - float(t0):6.1f} s  continuity {m['continuity']:.3f}"
      f" (resolved {m['continuity_resolved']:.3f}) islands {m['islands']} flipped {m['flipped']:.4f} L2 {m['l2_stretch']:.3f}"
      f" util {m['utilisation']:.3f} overlap {m['overlap']:.4f} | kept {kept}")
PY
