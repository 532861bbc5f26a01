// Non-cryptographic 128-bit hashing for content-addressed cache keys, file
// checksums and request fingerprints: XXH3-128 (libxxhash) over raw bytes,
// streamed, so values go in as their in-memory bytes, never as text.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace soupuv {

class Hasher {
 public:
  Hasher();
  ~Hasher();
  Hasher(Hasher&&) noexcept;
  Hasher& operator=(Hasher&&) noexcept;

  void add_bytes(const void* data, size_t size);
  // A value's bytes: only for types without padding (the bytes of padding
  // are unspecified and would make equal values hash differently).
  template <class T>
  void add(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    add_bytes(&value, sizeof(T));
  }
  // Length-prefixed, so ("ab", "") and ("a", "b") differ.
  void add(std::string_view s) { add(uint64_t(s.size())); add_bytes(s.data(), s.size()); }
  // A whole array in one call (length-prefixed), e.g. a soup's positions.
  template <class T>
  void add_array(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    add(uint64_t(values.size()));
    add_bytes(values.data(), values.size() * sizeof(T));
  }
  std::string hex() const;  // 32 hex digits

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// XXH3-64 of a buffer, for in-memory hash tables.
uint64_t hash64(const void* data, size_t size);

}  // namespace soupuv
