#!/usr/bin/env bash
# cli.field.metrics_agree — the diagnostics' uv.utilisation and uv.overlap are the
# yardstick's (../shared/eval/uvmetrics.py) on the same output: soupuv maps a
# few corpus soups (also with --method box, whose tri-planar maps do overlap,
# so the overlap figures compared are not all zero) and both scores must agree.
# usage: metrics_agree.sh SOUPUV EVAL_DIR CORPUS_DIR OUTDIR
set -euo pipefail
soupuv=$1 eval_dir=$2 corpus=$3 out=$4
mkdir -p "$out"
py=/usr/bin/python3
compared=0 overlapping=0
for run in "ThreeMeshes" "SpheresScaledInstances" "lamp" "SpheresScaledInstances --method box" \
           "lamp --method box"; do
  set -- $run
  name=$1; shift
  tag=$name$(printf '%s' "$*" | tr -c 'a-z' '_')
  "$soupuv" map "$corpus/$name-soup.glb" -o "$out/$tag.glb" --diagnostics "$out/$tag.json" --progress none "$@" >/dev/null 2>&1
  "$py" "$eval_dir/uvmetrics.py" "$corpus/$name-soup.ref.npz" "$out/$tag.glb" --json | tail -1 > "$out/$tag.eval.json"
  verdict=$("$py" - "$out/$tag.json" "$out/$tag.eval.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))["uv"]; e = json.load(open(sys.argv[2]))
du = abs(d["utilisation"] - e["utilisation"]); do = abs(d["overlap"] - e["overlap"])
ok = du <= 1e-3 * max(1.0, e["utilisation"]) and do <= 2e-3
print(("ok" if ok else "DIFFER"), "utilisation", d["utilisation"], e["utilisation"], "overlap", d["overlap"], e["overlap"])
PY
)
  echo "$tag: $verdict"
  case $verdict in ok*) ;; *) exit 1 ;; esac
  compared=$((compared + 1))
  if "$py" -c "import json,sys; sys.exit(0 if json.load(open('$out/$tag.eval.json'))['overlap'] > 0.01 else 1)"; then
    overlapping=$((overlapping + 1))
  fi
done
# The comparison must have seen a real overlap, or it proves little.
if [ "$overlapping" -eq 0 ]; then echo "no compared map overlapped: the test would not see a wrong overlap"; exit 1; fi
echo "$compared maps agree ($overlapping with overlap > 1 %)"
