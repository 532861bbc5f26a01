#!/usr/bin/env bash
# bench/unseen.sh [--seed S] [NAME ...]
# Soups soupuv has not seen, made the same way as the corpus: each corpus
# model's original mesh (NAME-soup.ref.npz: V, F) is written out and made
# into a soup again by ../shared/eval/make_soup.py with the corpus's noise
# amplitude and type but another seed (default 11; the corpus used 5). Draco
# soups are made with --draco when the evaluation's gltf-transform is
# installed (~/.cache/soupuv-eval, set up by ../shared/eval/compare.sh), and
# skipped otherwise. Each soup is then mapped and scored by bench/eval_one.sh
# (field uncached), and one line per soup says which of issue 19's quality
# targets it misses. Default NAMEs: every corpus soup but the two scans.
# Output soups and maps: OUT (default /tmp/soupuv-unseen).
# Needs /usr/bin/python3 with numpy and scipy (scripts/install-deps.sh).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
corpus=${CORPUS:-$here/../shared/data/corpus}
eval_dir=$here/../shared/eval
seed=11
if [ "${1:-}" = "--seed" ]; then seed=$2; shift 2; fi
out=${OUT:-/tmp/soupuv-unseen}
soups=$out/seed-$seed
mkdir -p "$soups"
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for f in "$corpus"/*-soup.ref.npz; do
    n=$(basename "$f" -soup.ref.npz)
    case $n in ogre|beast) ;; *) names+=("$n") ;; esac
  done
fi
draco_eval=$HOME/.cache/soupuv-eval
for n in "${names[@]}"; do
  ref=$corpus/$n-soup.ref.npz
  [ -f "$soups/$n-soup.glb" ] && continue
  read -r noise noise_type draco < <(/usr/bin/python3 - "$ref" "$soups/$n-original.glb" "$eval_dir" <<'PY'
import sys
import numpy as np
ref, out, eval_dir = sys.argv[1:4]
sys.path.insert(0, eval_dir)
import gltfio
d = np.load(ref)
gltfio.write_glb(out, d["V"], d["F"].reshape(-1))
print(float(d["noise"]), str(d["noise_type"]), int(bool(d["draco"])))
PY
  )
  flags=(--noise "$noise" --noise-type "$noise_type" --seed "$seed")
  make=$eval_dir/make_soup.py
  if [ "$draco" = 1 ]; then
    if [ ! -x "$draco_eval/node_modules/.bin/gltf-transform" ]; then
      echo "$n: skipped (a Draco soup needs $draco_eval from ../shared/eval/compare.sh)"
      continue
    fi
    flags+=(--draco)
    make=$draco_eval/make_soup.py
  fi
  /usr/bin/python3 "$make" "$soups/$n-original.glb" "$soups/$n-soup.glb" "${flags[@]}" >/dev/null
done
for n in "${names[@]}"; do
  [ -f "$soups/$n-soup.glb" ] || continue
  line=$(CORPUS=$soups OUT=$out/maps-$seed "$here/bench/eval_one.sh" "$n") || { echo "$line"; continue; }
  misses=$(/usr/bin/python3 - "$line" <<'PY'
import re, sys
line = sys.argv[1]
def num(key):
    m = re.search(key + r" ([0-9.]+)", line)
    return float(m.group(1)) if m else None
checks = [("continuity(resolved) < 0.95", num(r"\(resolved") < 0.95),
          ("flipped > 0.5 %", num("flipped") > 0.005),
          ("L2 > 1.3", num("L2") > 1.3),
          ("overlap > 1 %", num("overlap") > 0.01),
          ("utilisation < 0.55", num("util") < 0.55)]
missed = [name for name, bad in checks if bad]
print("misses: " + ", ".join(missed) if missed else "meets the quality targets")
PY
  )
  echo "$line | $misses"
done
