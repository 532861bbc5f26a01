#include "soupuv/hash.h"

#include <cstdio>

namespace soupuv {

namespace {
uint64_t mix(uint64_t x) {  // splitmix64 finaliser
  x ^= x >> 30; x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27; x *= 0x94d049bb133111ebull;
  x ^= x >> 31;
  return x;
}
}  // namespace

void Hasher::add_bytes(const void* data, size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    a_ = (a_ ^ p[i]) * 0x100000001b3ull;
    b_ = (b_ ^ p[i]) * 0x00000100000001b3ull + 0x9e3779b97f4a7c15ull;
  }
}

std::string Hasher::hex() const {
  char buf[33];
  std::snprintf(buf, sizeof buf, "%016llx%016llx",
                static_cast<unsigned long long>(mix(a_ ^ mix(b_))),
                static_cast<unsigned long long>(mix(b_ + 0x632be59bd9b4e019ull)));
  return buf;
}

}  // namespace soupuv
