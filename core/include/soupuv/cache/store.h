// A content-addressed store for stage results (charges, field lines): a
// memory-bounded LRU in front of an optional directory shared by processes.
//
// Keys are hex strings made by cache_key(): a hash of everything the value
// depends on (soup geometry hash, stage name, stage parameters, algorithm
// version), so a key never needs invalidation — a changed input is a new key.
//
// The directory is safe to share between several worker processes: a value
// is written to a unique temporary file, flushed, then renamed into place
// (rename is atomic on POSIX), so readers see a complete file or none. Every
// file carries a header with the key, the size and a content hash; a file
// that does not check out is treated as a miss.
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace soupuv::cache {

using Bytes = std::vector<uint8_t>;

// Hash of the parts, in order (each length-prefixed), as 32 hex digits.
std::string cache_key(std::initializer_list<std::string_view> parts);

struct StoreOptions {
  size_t memory_bytes = size_t(512) << 20;  // LRU budget; 0 disables the memory layer
  std::string directory;                    // "" = memory only
};

struct StoreStats {
  size_t memory_hits = 0, disk_hits = 0, misses = 0, puts = 0, evictions = 0;
  size_t memory_bytes = 0, entries = 0;
  size_t corrupt_files = 0;  // files that failed the header check (treated as misses)
};

class Store {
 public:
  explicit Store(StoreOptions options = {});

  // The value for key, from memory or disk (a disk hit is promoted to memory),
  // or nullptr.
  std::shared_ptr<const Bytes> get(const std::string& key);

  // Stores the value in memory (evicting least recently used entries beyond
  // the budget) and, when a directory is set, on disk.
  void put(const std::string& key, Bytes value);

  StoreStats stats() const;
  const StoreOptions& options() const { return options_; }

 private:
  void insert_memory(const std::string& key, std::shared_ptr<const Bytes> value);
  std::shared_ptr<const Bytes> read_disk(const std::string& key);
  void write_disk(const std::string& key, const Bytes& value);
  std::string path_for(const std::string& key) const;

  StoreOptions options_;
  mutable std::mutex mutex_;
  std::list<std::pair<std::string, std::shared_ptr<const Bytes>>> lru_;  // front = newest
  std::unordered_map<std::string, decltype(lru_)::iterator> index_;
  StoreStats stats_;
};

}  // namespace soupuv::cache
