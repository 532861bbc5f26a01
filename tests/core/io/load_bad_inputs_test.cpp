// Malformed inputs: every file in shared/data/bad gives its specific error
// code and a one-line message; truncated and corrupted variants of every
// supported kind (GLB, GLB+Draco, glTF with data: URIs, raw .drc) give
// soupuv::Error or a consistent soup, never a crash (run under ASan/UBSan).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "load_test_support.h"
#include "soupuv/errors.h"
#include "soupuv/io/load.h"

using namespace soupuv;
using namespace soupuv::io;
using test::data_path;

namespace {

struct Bad {
  const char* file;
  ErrorCode code;
  const char* message_part;  // the reason must name the problem
};

const Bad kBad[] = {
    {"accessor-overrun.glb", ErrorCode::invalid_input, "exceeds its bufferView"},
    {"draco-garbage.glb", ErrorCode::invalid_input, "Draco"},
    {"empty.glb", ErrorCode::invalid_input, "empty"},
    {"external-uri.gltf", ErrorCode::unsupported, "external file"},
    {"index-oob.glb", ErrorCode::invalid_input, "uses vertex"},
    {"length-lie.glb", ErrorCode::invalid_input, "header length"},
    {"nan-position.glb", ErrorCode::invalid_input, "non-finite"},
    {"not-gltf.gltf", ErrorCode::invalid_input, "not"},
    {"points-only.glb", ErrorCode::no_triangles, "no triangles"},
    {"random.glb", ErrorCode::invalid_input, "GLB"},
    {"truncated.glb", ErrorCode::invalid_input, "header length"},
    {"point-cloud.drc", ErrorCode::no_triangles, "point cloud"},
};

// Loads and returns the error; fails the test when no Error is thrown.
Error expect_error(std::span<const uint8_t> bytes, const LoadOptions& options = {}) {
  try {
    load_memory(bytes, options);
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "loaded without error";
  return Error(ErrorCode::internal, "no error");
}

// A corrupted input either fails with soupuv::Error or loads into a soup that
// satisfies the loader's promises. Any other exception escapes and fails.
void load_or_error(std::span<const uint8_t> bytes) {
  LoadOptions o;
  o.max_bytes = 64 << 20;
  o.max_triangles = 1 << 20;
  try {
    Asset a = load_memory(bytes, o);
    ASSERT_FALSE(a.soup.triangles.empty());
    for (const Tri& t : a.soup.triangles)
      for (uint32_t v : t) ASSERT_LT(v, a.soup.positions.size());
    for (const Vec3& p : a.soup.positions) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z));
  } catch (const Error& e) {
    ASSERT_NE(e.code(), ErrorCode::internal) << e.what();
    ASSERT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

// A glTF (JSON) version of Triangle.gltf with its buffer as a data: URI.
std::vector<uint8_t> embedded_triangle() {
  auto doc = nlohmann::json::parse(test::read_bytes(data_path("gltf/Triangle/Triangle.gltf")));
  doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," +
                             test::base64(test::read_bytes(data_path("gltf/Triangle/simpleTriangle.bin")));
  std::string text = doc.dump(1);
  return {text.begin(), text.end()};
}

struct Kind {
  const char* name;
  std::vector<uint8_t> bytes;
};

std::vector<Kind> supported_kinds() {
  return {{"glb", test::read_bytes(data_path("gltf/Box.glb"))},
          {"glb+draco", test::read_bytes(data_path("gltf/Box_Draco.glb"))},
          {"gltf+data-uri", embedded_triangle()},
          {"drc", test::read_bytes(data_path("drc/cube_att.drc"))},
          {"drc-bigger", test::read_bytes(data_path("drc/test_nm.drc"))}};
}

}  // namespace

TEST(LoadBadInputs, EveryBadSampleGivesItsSpecificError) {
  for (const Bad& b : kBad) {
    SCOPED_TRACE(b.file);
    auto bytes = test::read_bytes(data_path(std::string("bad/") + b.file));
    Error e = expect_error(bytes);
    EXPECT_EQ(e.code(), b.code) << e.what();
    EXPECT_NE(std::string(e.what()).find(b.message_part), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    // load_file reaches the same verdict (the server never allows external URIs;
    // the CLI may, and external-uri.gltf must still be refused).
    LoadOptions cli;
    cli.allow_external_uris = true;
    try {
      load_file(data_path(std::string("bad/") + b.file), cli);
      ADD_FAILURE() << "load_file accepted it";
    } catch (const Error& e2) {
      EXPECT_EQ(e2.code(), b.code) << e2.what();
    }
  }
}

TEST(LoadBadInputs, GeneratedDataUriSampleLoads) {
  // The corruption test below is only meaningful if the intact file loads.
  EXPECT_EQ(load_memory(embedded_triangle()).soup.triangle_count(), 1u);
}

TEST(LoadBadInputs, TruncationsAtManyOffsetsAreErrors) {
  for (const Kind& k : supported_kinds()) {
    SCOPED_TRACE(k.name);
    ASSERT_GT(load_memory(k.bytes).soup.triangle_count(), 0u);
    const size_t n = k.bytes.size();
    size_t step = std::max<size_t>(1, n / 400);
    for (size_t cut = 0; cut < n; cut += step) {
      std::span<const uint8_t> prefix(k.bytes.data(), cut);
      try {
        load_memory(prefix);
        ADD_FAILURE() << "truncated at " << cut << " of " << n << " loaded";
      } catch (const Error& e) {
        EXPECT_NE(e.code(), ErrorCode::internal);
      }
    }
  }
}

TEST(LoadBadInputs, FlippedBytesGiveErrorsOrConsistentSoups) {
  std::mt19937 rng(7);
  for (const Kind& k : supported_kinds()) {
    SCOPED_TRACE(k.name);
    for (int trial = 0; trial < 300; ++trial) {
      std::vector<uint8_t> bytes = k.bytes;
      int flips = 1 + trial % 4;
      for (int f = 0; f < flips; ++f) {
        size_t at = rng() % bytes.size();
        bytes[at] = trial % 2 ? uint8_t(rng()) : uint8_t(bytes[at] ^ (1u << (rng() % 8)));
      }
      load_or_error(bytes);
    }
  }
}

TEST(LoadBadInputs, LimitsAreEnforced) {
  auto bytes = test::read_bytes(data_path("gltf/Duck.glb"));
  LoadOptions small_bytes;
  small_bytes.max_bytes = 1000;
  EXPECT_EQ(expect_error(bytes, small_bytes).code(), ErrorCode::limit_exceeded);
  LoadOptions few_triangles;
  few_triangles.max_triangles = 4211;  // Duck has 4212
  EXPECT_EQ(expect_error(bytes, few_triangles).code(), ErrorCode::limit_exceeded);
  few_triangles.max_triangles = 4212;
  EXPECT_EQ(load_memory(bytes, few_triangles).soup.triangle_count(), 4212u);
  auto draco = test::read_bytes(data_path("soups/spot-soup-draco.glb"));
  LoadOptions few_for_draco;
  few_for_draco.max_triangles = 1000;
  EXPECT_EQ(expect_error(draco, few_for_draco).code(), ErrorCode::limit_exceeded);
}
