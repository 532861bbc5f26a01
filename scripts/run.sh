#!/usr/bin/env bash
# The main job: install what the service needs (SOUPUV_DEPS=build: no test
# frameworks, chromium, nginx or clang), build Release, start soupuv-server with
# its embedded defaults on 127.0.0.1:8080 and a local data directory
# (./soupuv-data). Open http://127.0.0.1:8080/ for the upload page.
# Extra arguments go to soupuv-server (e.g. --workers 2, --port 9000).
set -euo pipefail
cd "$(dirname "$0")/.."
export CCACHE_BASEDIR="$(pwd)"
SOUPUV_DEPS=build bash scripts/install-deps.sh
# three.js for the upload page only (the dev dependencies are test tools).
if [ -f package-lock.json ]; then
  npm ci --omit=dev --no-audit --no-fund --loglevel=error
elif [ ! -d node_modules/three ]; then
  npm install --omit=dev --no-audit --no-fund --loglevel=error
fi
# No test suites: GoogleTest is a test extra (scripts/test.sh turns them on).
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DSOUPUV_BUILD_TESTS=OFF >/dev/null
cmake --build build/release -j "${SOUPUV_JOBS:-$(nproc)}" --target soupuv soupuv-server
echo "soupuv-server: http://127.0.0.1:8080/  (data in ./soupuv-data; Ctrl-C stops)"
exec build/release/server/soupuv-server --host 127.0.0.1 --port 8080 --data-dir ./soupuv-data "$@"
