#!/usr/bin/env bash
# cli.field.new_seeds_targets — issue 19's quality targets on soups made the
# corpus's way at seeds the defaults were not chosen on: each named corpus
# model's original (NAME-soup.ref.npz: V, F) made into a soup again by
# ../shared/eval/make_soup.py with the corpus's noise and another seed, mapped
# with the defaults and scored by ../shared/eval/uvmetrics.py. Every soup must
# have coverage 1, flipped <= 0.5 %, L2 stretch <= 1.3, overlap <= 1 % and
# utilisation >= 0.55 (continuity is not asserted here: the chosen models'
# continuity targets are either met by construction or out of reach, see
# docs/tuning.md, session 45). The seeds are ones that once missed a target.
# usage: new_seeds_targets.sh SOUPUV EVAL_DIR CORPUS_DIR OUTDIR NAME:SEED...
set -euo pipefail
soupuv=$1 eval_dir=$2 corpus=$3 out=$4
shift 4
mkdir -p "$out"
py=/usr/bin/python3
failed=0
for run in "$@"; do
  name=${run%%:*} seed=${run##*:}
  tag=$name-$seed
  read -r noise noise_type < <("$py" - "$corpus/$name-soup.ref.npz" "$out/$tag-original.glb" "$eval_dir" <<'PY'
import sys
import numpy as np
ref, out, eval_dir = sys.argv[1:4]
sys.path.insert(0, eval_dir)
import gltfio
d = np.load(ref)
gltfio.write_glb(out, d["V"], d["F"].reshape(-1))
print(float(d["noise"]), str(d["noise_type"]))
PY
  )
  "$py" "$eval_dir/make_soup.py" "$out/$tag-original.glb" "$out/$tag-soup.glb" \
    --noise "$noise" --noise-type "$noise_type" --seed "$seed" >/dev/null
  "$soupuv" map "$out/$tag-soup.glb" -o "$out/$tag.glb" --progress none >/dev/null 2>"$out/$tag.err"
  "$py" "$eval_dir/uvmetrics.py" "$out/$tag-soup.ref.npz" "$out/$tag.glb" --json | tail -1 > "$out/$tag.json"
  verdict=$("$py" - "$out/$tag.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
checks = [("coverage < 1", m["coverage"] < 1), ("flipped > 0.5 %", m["flipped"] > 0.005),
          ("L2 > 1.3", m["l2_stretch"] > 1.3), ("overlap > 1 %", m["overlap"] > 0.01),
          ("utilisation < 0.55", m["utilisation"] < 0.55)]
missed = [name for name, bad in checks if bad]
figures = "L2 %.3f utilisation %.3f overlap %.4f flipped %.4f" % (m["l2_stretch"], m["utilisation"], m["overlap"], m["flipped"])
print(("misses " + ", ".join(missed) if missed else "ok") + ": " + figures)
PY
)
  echo "$tag: $verdict"
  case $verdict in ok*) ;; *) failed=$((failed + 1)) ;; esac
done
[ "$failed" -eq 0 ] || { echo "$failed soups miss a target"; exit 1; }
echo "$# soups meet the targets"
