// libFuzzer target over io::load_memory: any byte string must either load into
// a soup that keeps the loader's promises or throw soupuv::Error. Anything
// else (a crash, a sanitizer report, another exception, a hang) is a finding.
// Built and run by scripts/fuzz.sh.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "soupuv/errors.h"
#include "soupuv/io/load.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Lets scripts/fuzz.sh prove that a finding fails the run.
  static const bool selftest = std::getenv("SOUPUV_FUZZ_SELFTEST") != nullptr;
  if (selftest && size >= 4 && data[0] == 'g' && data[1] == 'l' && data[2] == 'T' && data[3] == 'F') std::abort();
  soupuv::io::LoadOptions options;
  // Small limits keep each run fast and memory-bounded; the checks are the same.
  options.max_bytes = 16u << 20;
  options.max_triangles = 200'000;
  try {
    soupuv::io::Asset asset = soupuv::io::load_memory(std::span<const uint8_t>(data, size), options);
    const soupuv::Soup& soup = asset.soup;
    if (soup.triangles.empty() || soup.origins.size() != soup.triangles.size() ||
        asset.local_positions.size() != soup.positions.size())
      std::abort();
    for (const soupuv::Tri& t : soup.triangles)
      for (uint32_t v : t)
        if (v >= soup.positions.size()) std::abort();
    for (const soupuv::Vec3& p : soup.positions)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
  } catch (const soupuv::Error& e) {
    if (e.code() == soupuv::ErrorCode::internal) std::abort();
  }
  return 0;
}
