// A small non-cryptographic 128-bit hash (two independent 64-bit FNV-1a-style
// streams mixed with a strong finaliser) for content-addressed cache keys.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace soupuv {

class Hasher {
 public:
  void add_bytes(const void* data, size_t size);
  template <class T>
  void add(const T& value) { add_bytes(&value, sizeof(T)); }
  void add(std::string_view s) { add(s.size()); add_bytes(s.data(), s.size()); }
  std::string hex() const;  // 32 hex digits

 private:
  uint64_t a_ = 0xcbf29ce484222325ull;
  uint64_t b_ = 0x84222325cbf29ce4ull;
};

}  // namespace soupuv
