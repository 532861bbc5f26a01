#!/usr/bin/env bash
# Installs every Debian package soupuv needs to build, test and run. Idempotent:
# packages already present are skipped, so a second run costs one dpkg query.
#   SOUPUV_DEPS=build  only what building and running the service needs
#                      (scripts/run.sh, the Docker build stage: no test
#                      frameworks, browsers, web servers or clang)
#   --print            list the packages and exit, installing nothing
set -euo pipefail

# Build and run: compilers and CMake, the libraries the binaries link, and
# Node.js + npm for the upload page's three.js (npm ci --omit=dev).
build_packages=(
  build-essential cmake ninja-build ccache pkg-config git
  libcpp-httplib-dev nlohmann-json3-dev libtinygltf-dev libstb-dev libdraco-dev
  libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libspdlog-dev libfmt-dev libsqlite3-dev libssl-dev libpq-dev libzip-dev
  libcli11-dev libxxhash-dev
)
# Tests only: GoogleTest, clang + libFuzzer and OpenMP for it (fuzz target),
# chromium (browser test), nginx (reverse-proxy test), curl, python3-yaml
# (deploy-file checks), python3-numpy + python3-scipy (cli.field.metrics_agree runs
# ../shared/eval/uvmetrics.py), python3 (the Python client's tests), postgresql (the
# PostgreSQL store's contract tests, the cluster test and `soupuv-bench store` start a server
# of their own in a temp directory with its initdb + pg_ctl; the package's cluster is unused).
# libpq-dev above is the client library the server links for --database-url.
test_packages=(
  libgtest-dev libgmock-dev
  clang libclang-rt-14-dev libomp-dev
  chromium nginx-light curl python3 python3-yaml python3-numpy python3-scipy
  postgresql
)
packages=("${build_packages[@]}")
[ "${SOUPUV_DEPS:-all}" = build ] || packages+=("${test_packages[@]}")
if [ "${1:-}" = --print ]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "all Debian packages present"
fi

# Node.js and npm come with the machine image (npm bundled with nodejs, which
# conflicts with Debian's separate npm package); install Debian's only if absent.
if ! command -v npm >/dev/null 2>&1; then
  ${SUDO:-} apt-get install -y -qq --no-install-recommends nodejs npm
fi
