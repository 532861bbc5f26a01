#!/usr/bin/env bash
# Installs, builds and runs every test: the README's test command, and what
# .ci/run calls. Two build trees: release (every suite, benchmarks in --quick
# mode) and asan (AddressSanitizer + UBSan over the suites facing untrusted
# input and the numeric kernels: field, proxy, atlas, at reduced sizes).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
# ccache hits across clones at other paths (CI builds a fresh clone).
export CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=1
jobs=${SOUPUV_JOBS:-$(nproc)}

bash scripts/install-deps.sh
if [ -f package-lock.json ]; then
  npm ci --no-audit --no-fund --loglevel=error
fi

# Tests that need ../shared/data skip (ctest "Skipped") with their reason when
# it is absent; the counts are printed at the end.
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
skipped() { grep -c '(Skipped)' "$1" || true; }
if [ ! -d "$root/../shared/data" ]; then
  echo "note: ../shared/data is absent: the tests that need it will be skipped"
fi

echo "== release build"
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DSOUPUV_BUILD_TESTS=ON >/dev/null
cmake --build build/release -j "$jobs"
echo "== release tests"
# The request-path property test (tests/server/request_fuzz_test.cpp) runs a
# full minute in CI; a plain ctest run gives it 10 s.
SOUPUV_REQUEST_FUZZ_SECONDS=${SOUPUV_REQUEST_FUZZ_SECONDS:-60} \
  ctest --test-dir build/release --output-on-failure -j "$jobs" --timeout 900 | tee "$logs/release.txt"

echo "== sanitizer build (ASan + UBSan), at ${SECONDS}s"
cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSOUPUV_SANITIZE=ON \
      -DSOUPUV_BUILD_SERVER=OFF >/dev/null
# Only the SANITIZE suites (tests/CMakeLists.txt: those facing untrusted input,
# and field, proxy and atlas for their SIMD kernels and padded arrays) and the
# CLI are built here, to keep CI short.
suites=$(tr ';' ' ' < build/asan/sanitize_suites.txt)
# The target list goes into a variable, never straight into `grep -q`: under
# pipefail, grep quitting at its first match can kill ninja with SIGPIPE and
# the test reads as false (the CLI was once left unbuilt that way).
known=$(ninja -C build/asan -t targets all | sed 's/:.*//')
has_target() { grep -qx "$1" <<< "$known"; }
targets=""; regex=""
for s in $suites; do
  regex="$regex|^$s\\."
  if has_target "soupuv_tests_$s"; then targets="$targets soupuv_tests_$s"; fi
done
if has_target soupuv; then targets="$targets soupuv"; else echo "no soupuv target in build/asan" >&2; exit 1; fi
cmake --build build/asan -j "$jobs" --target $targets
echo "== sanitizer tests, at ${SECONDS}s"
# SOUPUV_TEST_SIZE=reduced: the slow tests run smaller or, when they only
# measure scale, are skipped (tests/support/test_size.h).
SOUPUV_TEST_SIZE=reduced ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build/asan --output-on-failure -j "$jobs" --timeout 900 -R "${regex#|}" \
        -E '^cli\.field\.' | tee "$logs/asan.txt"  # the field method end to end is minutes under ASan; its parts run above

if [ -x scripts/fuzz.sh ]; then
  echo "== fuzzing (bounded)"
  bash scripts/fuzz.sh
fi
echo "== all tests passed in ${SECONDS}s; skipped: $(skipped "$logs/release.txt") release, $(skipped "$logs/asan.txt") sanitizer"
grep -h '(Skipped)' "$logs/release.txt" "$logs/asan.txt" | sed 's/^/   skipped: /' || true
