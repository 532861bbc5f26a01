#include <gtest/gtest.h>

#include <vector>

#include "soupuv/hash.h"

using namespace soupuv;

// Cache keys must mean the same across builds and machines: the digest is
// XXH3-128 itself (the empty input's published value), high half first.
TEST(Hash, IsXxh3Of128Bits) { EXPECT_EQ(Hasher().hex(), "99aa06d3014798d86001c324468d497f"); }

TEST(Hash, StreamedPiecesHashLikeTheWhole) {
  std::vector<double> values(1000);
  for (size_t i = 0; i < values.size(); ++i) values[i] = 0.1 * double(i);
  Hasher whole, pieces;
  whole.add_bytes(values.data(), values.size() * sizeof(double));
  for (double v : values) pieces.add(v);
  EXPECT_EQ(whole.hex(), pieces.hex());
}

TEST(Hash, ArraysAndStringsAreLengthPrefixed) {
  Hasher a, b;
  a.add_array(std::vector<uint32_t>{1, 2});
  a.add_array(std::vector<uint32_t>{3});
  b.add_array(std::vector<uint32_t>{1});
  b.add_array(std::vector<uint32_t>{2, 3});
  EXPECT_NE(a.hex(), b.hex());
}
