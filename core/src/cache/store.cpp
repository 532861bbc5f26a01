#include "soupuv/cache/store.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include "soupuv/hash.h"

namespace soupuv::cache {

namespace fs = std::filesystem;

namespace {

// File layout version: C2 since the content hash became XXH3. A C1 file sits
// under a key no new key equals (kKeyVersion), and would fail this check.
constexpr char kMagic[8] = {'S', 'O', 'U', 'P', 'U', 'V', 'C', '2'};

// Hashed ahead of every key's parts: keys made by another hash or another key
// layout can never equal one of these. Bump it when either changes.
constexpr std::string_view kKeyVersion = "soupuv-cache-key/xxh3-128/1";

std::string content_hash(const uint8_t* data, size_t size) {
  Hasher h;
  h.add_bytes(data, size);
  return h.hex();
}

// Writes all of `data` to fd; false on any error.
bool write_all(int fd, const uint8_t* data, size_t size) {
  while (size > 0) {
    ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= size_t(n);
  }
  return true;
}

}  // namespace

std::string cache_key(std::initializer_list<std::string_view> parts) {
  Hasher h;
  h.add(kKeyVersion);
  for (std::string_view p : parts) h.add(p);
  return h.hex();
}

Store::Store(StoreOptions options) : options_(std::move(options)) {}

std::string Store::path_for(const std::string& key) const {
  // Two-character fan-out keeps directories small with many entries.
  return (fs::path(options_.directory) / key.substr(0, 2) / (key + ".bin")).string();
}

std::shared_ptr<const Bytes> Store::get(const std::string& key) {
  {
    std::lock_guard lock(mutex_);
    auto it = index_.find(key);
    if (it != index_.end()) {
      lru_.splice(lru_.begin(), lru_, it->second);
      ++stats_.memory_hits;
      return it->second->second;
    }
  }
  if (!options_.directory.empty()) {
    auto value = read_disk(key);
    if (value) {
      std::lock_guard lock(mutex_);
      ++stats_.disk_hits;
      insert_memory(key, value);
      return value;
    }
  }
  std::lock_guard lock(mutex_);
  ++stats_.misses;
  return nullptr;
}

void Store::put(const std::string& key, Bytes value) {
  auto shared = std::make_shared<const Bytes>(std::move(value));
  if (!options_.directory.empty()) write_disk(key, *shared);
  std::lock_guard lock(mutex_);
  ++stats_.puts;
  insert_memory(key, shared);
}

void Store::insert_memory(const std::string& key, std::shared_ptr<const Bytes> value) {
  // Caller holds mutex_.
  if (value->size() > options_.memory_bytes) return;  // would evict everything for nothing
  auto it = index_.find(key);
  if (it != index_.end()) {
    stats_.memory_bytes -= it->second->second->size();
    lru_.erase(it->second);
    index_.erase(it);
  }
  lru_.emplace_front(key, value);
  index_[key] = lru_.begin();
  stats_.memory_bytes += value->size();
  while (stats_.memory_bytes > options_.memory_bytes && !lru_.empty()) {
    auto& last = lru_.back();
    stats_.memory_bytes -= last.second->size();
    index_.erase(last.first);
    lru_.pop_back();
    ++stats_.evictions;
  }
  stats_.entries = lru_.size();
}

std::shared_ptr<const Bytes> Store::read_disk(const std::string& key) {
  std::ifstream in(path_for(key), std::ios::binary);
  if (!in) return nullptr;
  Bytes file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Header: magic, key length + key, payload size, payload hash (32 hex).
  auto corrupt = [&]() -> std::shared_ptr<const Bytes> {
    std::lock_guard lock(mutex_);
    ++stats_.corrupt_files;
    return nullptr;
  };
  size_t pos = 0;
  auto take = [&](void* out, size_t n) {
    if (file.size() - pos < n) return false;
    std::memcpy(out, file.data() + pos, n);
    pos += n;
    return true;
  };
  char magic[8];
  uint32_t key_len = 0;
  uint64_t size = 0;
  char hash[32];
  if (!take(magic, 8) || std::memcmp(magic, kMagic, 8) != 0) return corrupt();
  if (!take(&key_len, 4) || key_len != key.size() || file.size() - pos < key_len) return corrupt();
  if (std::memcmp(file.data() + pos, key.data(), key_len) != 0) return corrupt();
  pos += key_len;
  if (!take(&size, 8) || !take(hash, 32) || file.size() - pos != size) return corrupt();
  if (content_hash(file.data() + pos, size) != std::string(hash, 32)) return corrupt();
  return std::make_shared<const Bytes>(file.begin() + long(pos), file.end());
}

void Store::write_disk(const std::string& key, const Bytes& value) {
  static std::atomic<uint64_t> counter{0};
  std::error_code ec;
  fs::path final_path = path_for(key);
  fs::create_directories(final_path.parent_path(), ec);  // racing creators are fine
  if (ec) return;  // the cache is an optimisation: a read-only directory is not an error
  // Unique per process, thread and call, in the same directory (same file
  // system) so rename() is atomic.
  std::string tmp = final_path.string() + ".tmp." + std::to_string(::getpid()) + "." +
                    std::to_string(std::hash<std::thread::id>()(std::this_thread::get_id())) + "." +
                    std::to_string(counter++);
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return;
  uint32_t key_len = uint32_t(key.size());
  uint64_t size = value.size();
  std::string hash = content_hash(value.data(), value.size());
  bool ok = write_all(fd, reinterpret_cast<const uint8_t*>(kMagic), 8) &&
            write_all(fd, reinterpret_cast<const uint8_t*>(&key_len), 4) &&
            write_all(fd, reinterpret_cast<const uint8_t*>(key.data()), key.size()) &&
            write_all(fd, reinterpret_cast<const uint8_t*>(&size), 8) &&
            write_all(fd, reinterpret_cast<const uint8_t*>(hash.data()), 32) &&
            write_all(fd, value.data(), value.size()) && ::fsync(fd) == 0;
  ok = (::close(fd) == 0) && ok;
  if (!ok || std::rename(tmp.c_str(), final_path.c_str()) != 0) std::remove(tmp.c_str());
}

StoreStats Store::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace soupuv::cache
