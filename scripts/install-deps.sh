#!/usr/bin/env bash
# Installs every Debian package soupuv needs to build, test and run. Idempotent:
# packages already present are skipped, so a second run costs one dpkg query.
#   SOUPUV_DEPS=build  only what building the binaries needs (the Docker build
#                      stage: no test frameworks, browsers or web servers)
#   --print            list the packages and exit, installing nothing
set -euo pipefail

build_packages=(
  build-essential cmake ninja-build ccache pkg-config git
  libcpp-httplib-dev nlohmann-json3-dev libtinygltf-dev libstb-dev libdraco-dev
  libeigen3-dev libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libspdlog-dev libfmt-dev libsqlite3-dev libssl-dev
  libcli11-dev libxxhash-dev
)
# Tests only: GoogleTest, clang + libFuzzer and OpenMP for it (fuzz target),
# chromium (browser test), nginx (reverse-proxy test), curl, python3-yaml
# (deploy-file checks), python3-numpy + python3-scipy (cli.field.metrics_agree runs
# ../shared/eval/uvmetrics.py).
test_packages=(
  libgtest-dev libgmock-dev
  clang libclang-rt-14-dev libomp-dev
  chromium nginx-light curl python3-yaml python3-numpy python3-scipy
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
