#!/usr/bin/env bash
# cli.external_files — a .gltf's buffers beside it (or below it) are read by
# default; --no-external-files refuses them (exit 4); a URI climbing out with
# '..', an absolute path, a URL, or a symlink leading out of the folder is
# refused whatever the flags (exit 4), with one clean "soupuv: " line.
# usage: external_files.sh SOUPUV SAMPLE_DIR(with Triangle/) WORKDIR
set -euo pipefail
soupuv=$1 triangle=$2/Triangle work=$3
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work/model/buffers" "$work/outside"
gltf() {  # gltf URI > file: Triangle.gltf with its buffer URI replaced
  sed "s#\"simpleTriangle.bin\"#\"$1\"#" "$triangle/Triangle.gltf"
}
cp "$triangle/simpleTriangle.bin" "$work/model/buffers/tri.bin"
cp "$triangle/simpleTriangle.bin" "$work/outside/tri.bin"
gltf buffers/tri.bin > "$work/model/below.gltf"
gltf ../outside/tri.bin > "$work/model/climb.gltf"
gltf "$work/outside/tri.bin" > "$work/model/absolute.gltf"
gltf https://example.com/tri.bin > "$work/model/url.gltf"
ln -s ../outside "$work/model/link"
gltf link/tri.bin > "$work/model/symlink.gltf"

echo "== a buffer in a subfolder is read by default"
"$soupuv" map "$work/model/below.gltf" -o "$work/below.glb" --method box --progress none
echo "== --no-external-files refuses it"
bash "$here/expect_clean_failure.sh" --message "no-external-files" 4 \
  "$soupuv" map "$work/model/below.gltf" -o "$work/x.glb" --method box --progress none --no-external-files
bash "$here/expect_clean_failure.sh" 4 "$soupuv" inspect "$work/model/below.gltf" --no-external-files
for bad in climb absolute url symlink; do
  echo "== $bad refused"
  bash "$here/expect_clean_failure.sh" 4 "$soupuv" map "$work/model/$bad.gltf" -o "$work/x.glb" --method box --progress none
done
echo "external files: all checks passed"
