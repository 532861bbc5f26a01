#include "soupuv/server/storage.h"

#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

namespace soupuv::server {
namespace fs = std::filesystem;

int64_t free_bytes(const fs::path& path) {
  struct statvfs st;
  if (statvfs(path.c_str(), &st) != 0) return -1;
  return int64_t(st.f_bavail) * int64_t(st.f_frsize);
}

StorageStatus storage_status(const fs::path& dir, int64_t min_free_bytes) {
  StorageStatus s;
  s.free = free_bytes(dir);
  s.enough_space = s.free >= 0 && s.free >= min_free_bytes;
  // access(W_OK) says yes on a read-only mount or a full inode table; only a
  // real create answers the question.
  const fs::path probe = dir / (".readyz-probe." + std::to_string(getpid()));
  int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd >= 0) {
    s.writable = ::write(fd, "ok", 2) == 2;
    ::close(fd);
    ::unlink(probe.c_str());
  }
  return s;
}

namespace {

bool is_temp_name(const std::string& name) {
  return name.size() > 4 && (name.compare(name.size() - 4, 4, ".tmp") == 0 || name.find(".tmp.") != std::string::npos);
}

}  // namespace

int sweep_stale_temp_files(const fs::path& data_root, std::chrono::seconds min_age) {
  int removed = 0;
  const auto now = fs::file_time_type::clock::now();
  for (const fs::path& dir : {data_root / "cache", data_root / "jobs"}) {
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, fs::directory_options::skip_permission_denied, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
      std::error_code fe;
      if (!it->is_regular_file(fe) || !is_temp_name(it->path().filename().string())) continue;
      auto mtime = fs::last_write_time(it->path(), fe);
      if (fe || now - mtime < min_age) continue;  // a write may still be in progress
      if (fs::remove(it->path(), fe)) ++removed;
    }
  }
  return removed;
}

}  // namespace soupuv::server
