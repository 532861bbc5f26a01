#!/usr/bin/env bash
# The main job: install dependencies, build Release, start soupuv-server with
# its embedded defaults on 127.0.0.1:8080 and a local data directory
# (./soupuv-data). Open http://127.0.0.1:8080/ for the upload page.
# Extra arguments go to soupuv-server (e.g. --workers 2, --port 9000).
set -euo pipefail
cd "$(dirname "$0")/.."
export CCACHE_BASEDIR="$(pwd)"
bash scripts/install-deps.sh
if [ -f package-lock.json ]; then
  npm ci --no-audit --no-fund --loglevel=error
elif [ ! -d node_modules/three ]; then
  npm install --no-audit --no-fund --loglevel=error
fi
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "${SOUPUV_JOBS:-$(nproc)}" --target soupuv soupuv-server
echo "soupuv-server: http://127.0.0.1:8080/  (data in ./soupuv-data; Ctrl-C stops)"
exec build/release/server/soupuv-server --host 127.0.0.1 --port 8080 --data-dir ./soupuv-data "$@"
