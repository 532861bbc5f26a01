#include <gtest/gtest.h>

#include "soupuv/cache/store.h"
#include "soupuv/hash.h"

using namespace soupuv;

// A version tag goes ahead of the parts, so keys made by an earlier hash or
// key layout can never name one of these entries.
TEST(CacheKey, CarriesAVersionTag) {
  Hasher bare;
  bare.add(std::string_view("a"));
  EXPECT_NE(cache::cache_key({"a"}), bare.hex());
  EXPECT_EQ(cache::cache_key({"a", "b"}), cache::cache_key({"a", "b"}));
}
