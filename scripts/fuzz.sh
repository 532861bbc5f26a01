#!/usr/bin/env bash
# Bounded libFuzzer run over the loader (io::load_memory) with ASan + UBSan,
# seeded with the shared samples and the bad files. Exits non-zero when the
# fuzzer finds a crash, a sanitizer error, a leak or a timeout; the input that
# triggered it is left in build/fuzz/artifacts/.
#
#   scripts/fuzz.sh [SECONDS]      (default 60; env SOUPUV_SHARED_DATA, CXX)
#
# The loader and base sources are compiled directly with clang++ (libFuzzer
# needs clang; the project itself builds with g++), so this needs no CMake tree.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
seconds=${1:-60}
data=${SOUPUV_SHARED_DATA:-$root/../shared/data}
cxx=${CXX_FUZZ:-clang++}
out=$root/build/fuzz
mkdir -p "$out/obj" "$out/corpus" "$out/artifacts"

# The loader's own sources (not the writer's, which share core/src/io/).
loader_sources="checked_json glb_container data_uri buffer_table accessors draco_decode
                primitive_geometry skin_attributes scene_flatten source_images source_skins load"
flags="-std=c++20 -g -O1 -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
       -I$root/core/include -I$root/core/src"
objects=""
compile() {  # source object: rebuild only when the source is newer
  if [ ! -f "$2" ] || [ "$1" -nt "$2" ] || [ -n "$(find "$root/core/include" "$root/core/src/io" -name '*.h' -newer "$2" -print -quit)" ]; then
    $cxx $flags -c "$1" -o "$2"
  fi
  objects="$objects $2"
}
for s in $loader_sources; do compile "$root/core/src/io/$s.cpp" "$out/obj/io_$s.o"; done
for f in "$root"/core/src/*.cpp; do compile "$f" "$out/obj/base_$(basename "$f" .cpp).o"; done
compile "$root/tests/fuzz/load_fuzzer.cpp" "$out/obj/load_fuzzer.o"
$cxx -fsanitize=fuzzer,address,undefined $objects -ldraco -o "$out/load_fuzzer"
# SOUPUV_FUZZ_SELFTEST=1 plants a crash on inputs starting with "glTF" to show
# that a finding makes this script fail (see tests/fuzz/load_fuzzer.cpp).

seeds=()
for d in gltf drc soups bad; do [ -d "$data/$d" ] && seeds+=("$data/$d"); done
echo "fuzzing io::load_memory for ${seconds}s (seeds: ${seeds[*]:-none})"
# New inputs go to build/fuzz/corpus; the shared seeds are only read.
set +e
ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  "$out/load_fuzzer" "$out/corpus" "${seeds[@]}" \
    -max_total_time="$seconds" -timeout=20 -rss_limit_mb=3072 -max_len=262144 \
    -artifact_prefix="$out/artifacts/" -print_final_stats=1 2>&1 | tail -n 40
status=${PIPESTATUS[0]}
set -e
if [ "$status" -ne 0 ]; then
  echo "fuzz: FINDING (exit $status); reproducer in $out/artifacts/" >&2
  exit "$status"
fi
echo "fuzz: no findings in ${seconds}s"
