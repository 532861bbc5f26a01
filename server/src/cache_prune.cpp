// prune_cache: see cache_prune.h. O(n log n) in the number of cache files.
#include "soupuv/server/cache_prune.h"

#include <sys/stat.h>

#include <algorithm>
#include <string>
#include <vector>

namespace soupuv::server {
namespace fs = std::filesystem;

namespace {

struct Entry {
  fs::path path;
  int64_t bytes;
  int64_t used_ns;  // max(atime, mtime)
};

int64_t ns(const timespec& t) { return int64_t(t.tv_sec) * 1000000000 + t.tv_nsec; }

}  // namespace

CachePruneResult prune_cache(const fs::path& dir, int64_t budget_bytes) {
  CachePruneResult r;
  std::vector<Entry> entries;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, fs::directory_options::skip_permission_denied, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->path().extension() != ".bin") continue;  // temp files of a write in progress are not ours
    struct stat st;
    if (lstat(it->path().c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    entries.push_back({it->path(), int64_t(st.st_size), std::max(ns(st.st_atim), ns(st.st_mtim))});
    r.bytes_before += int64_t(st.st_size);
  }
  r.bytes_after = r.bytes_before;
  if (r.bytes_before <= budget_bytes) return r;
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.used_ns < b.used_ns; });
  for (const auto& e : entries) {
    if (r.bytes_after <= budget_bytes) break;
    if (fs::remove(e.path, ec)) {
      r.bytes_after -= e.bytes;
      ++r.files_removed;
    }
  }
  return r;
}

}  // namespace soupuv::server
