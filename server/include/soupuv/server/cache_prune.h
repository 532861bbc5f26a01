// Keeps the workers' shared field cache (DATA/cache/, written by `soupuv map
// --cache-dir`) under the --cache-size-mb budget. The CLI's store has no disk
// bound of its own; the server owns the directory, so its sweeper prunes it.
//
// Input: the cache directory and a byte budget. Output: what was removed.
// Entries (`*.bin`) go least recently used first, judged by the later of
// access and modification time (with relatime, a read after a write counts).
// Removing a file a worker is reading is safe (its open descriptor stays
// valid); a removed entry is a cache miss, never an error.
#pragma once

#include <cstdint>
#include <filesystem>

namespace soupuv::server {

struct CachePruneResult {
  int64_t bytes_before = 0, bytes_after = 0;
  int64_t files_removed = 0;
};

CachePruneResult prune_cache(const std::filesystem::path& dir, int64_t budget_bytes);

}  // namespace soupuv::server
