// BlobStore::get, shared by both stores: read() in pieces into a temp file
// next to `to`, fsync, rename (files.h), so a reader of `to` sees the whole
// blob or nothing.
#include "soupuv/server/blob_store.h"

#include <limits>

#include "soupuv/server/files.h"

namespace soupuv::server {
namespace fs = std::filesystem;

bool BlobStore::get(const std::string& id, const std::string& name, const fs::path& to) {
  auto n = size(id, name);
  if (!n) return false;
  const fs::path tmp = to.string() + ".tmp";
  bool ok = false;
  {
    BoundedFileWriter out(tmp, std::numeric_limits<int64_t>::max());
    ok = read(id, name, 0, *n, [&](const char* p, size_t len) { return out.write(p, len); });
    out.finish();
  }
  if (!ok) {
    std::error_code ec;
    fs::remove(tmp, ec);
    return false;
  }
  commit_file(tmp, to);
  return true;
}

}  // namespace soupuv::server
