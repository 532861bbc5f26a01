#include "soupuv/server/files.h"

#include "soupuv/server/storage.h"

#include <fcntl.h>
#include <sys/random.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace soupuv::server {
namespace fs = std::filesystem;
namespace {

constexpr char kBase32[] = "abcdefghijklmnopqrstuvwxyz234567";
constexpr size_t kIdChars = 26;  // 130 bits of base32, 128 of them random

// A full disk or quota is the storage's condition, not a bug: its own type
// (503 + Retry-After at the API, storage.h); other errors stay runtime_error.
[[noreturn]] void fail(const std::string& what, const fs::path& p) {
  const int err = errno;
  std::string msg = what + " " + p.string() + ": " + std::strerror(err);
  if (err == ENOSPC || err == EDQUOT || err == EROFS) throw StorageUnavailable(msg);
  throw std::runtime_error(msg);
}

// A rename is durable only once its directory is: the fsync's result counts.
void fsync_dir(const fs::path& dir) {
  int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) fail("open dir", dir);
  int rc = ::fsync(fd);
  int err = errno;
  ::close(fd);
  errno = err;
  if (rc != 0) fail("fsync dir", dir);
}

}  // namespace

std::string new_job_id() {
  unsigned char bytes[17] = {};
  size_t got = 0;
  while (got < 16) {
    ssize_t n = getrandom(bytes + got, 16 - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("getrandom failed");
    }
    got += size_t(n);
  }
  std::string id = "j";
  uint32_t acc = 0;
  int bits = 0;
  size_t i = 0;
  while (id.size() < 1 + kIdChars) {
    if (bits < 5) {
      acc = (acc << 8) | bytes[i++];
      bits += 8;
    }
    id += kBase32[(acc >> (bits - 5)) & 31];
    bits -= 5;
  }
  return id;
}

bool is_valid_job_id(std::string_view id) {
  if (id.size() != 1 + kIdChars || id[0] != 'j') return false;
  for (char c : id.substr(1))
    if (!((c >= 'a' && c <= 'z') || (c >= '2' && c <= '7'))) return false;
  return true;
}

DataDir::DataDir(fs::path root) : root_(std::move(root)) {
  fs::create_directories(root_ / "jobs");
  fs::create_directories(cache());
  fs::create_directories(uploads_tmp());
}

fs::path DataDir::job(const std::string& id) const {
  if (!is_valid_job_id(id)) throw std::invalid_argument("invalid job id");
  return root_ / "jobs" / id;
}

void fsync_path(const fs::path& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail("open", path);
  int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) fail("fsync", path);
}

void commit_file(const fs::path& from, const fs::path& to) {
  fsync_path(from);
  if (::rename(from.c_str(), to.c_str()) != 0) fail("rename", from);
  fsync_dir(to.parent_path());
}

void write_file_atomic(const fs::path& path, std::string_view bytes) {
  fs::path tmp = path;
  tmp += ".tmp";
  {
    BoundedFileWriter w(tmp, int64_t(bytes.size()));
    w.write(bytes.data(), bytes.size());
    w.finish();
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) fail("rename", tmp);
  fsync_dir(path.parent_path());
}

std::string read_file(const fs::path& path, int64_t max_bytes) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail("open", path);
  std::string out;
  char buf[65536];
  for (;;) {
    ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    if (int64_t(out.size()) + n > max_bytes) {
      ::close(fd);
      throw std::runtime_error("file too large: " + path.filename().string());
    }
    out.append(buf, size_t(n));
  }
  ::close(fd);
  return out;
}

BoundedFileWriter::BoundedFileWriter(const fs::path& path, int64_t budget) : path_(path), budget_(budget) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0640);
  if (fd_ < 0) fail("create", path);
}

BoundedFileWriter::~BoundedFileWriter() {
  if (fd_ >= 0) ::close(fd_);
}

bool BoundedFileWriter::write(const char* data, size_t n) {
  if (over_ || bytes_ + int64_t(n) > budget_) {
    over_ = true;
    return false;
  }
  while (n > 0) {
    ssize_t w = ::write(fd_, data, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      fail("write", path_);
    }
    data += w;
    n -= size_t(w);
    bytes_ += w;
  }
  return true;
}

void BoundedFileWriter::finish() {
  if (fd_ < 0) return;
  int rc = ::fsync(fd_);
  int err = errno;
  ::close(fd_);
  errno = err;
  fd_ = -1;
  if (rc != 0) fail("fsync", path_);
}

}  // namespace soupuv::server
