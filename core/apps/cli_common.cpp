// Exit codes, atomic file output and format names for the CLI (see cli.h).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fcntl.h>
#include <unistd.h>

#include "cli.h"

namespace soupuv::cli {

int exit_code(ErrorCode code) {
  switch (code) {
    case ErrorCode::invalid_input: return kInvalidInput;
    case ErrorCode::unsupported: return kUnsupported;
    case ErrorCode::limit_exceeded: return kLimitExceeded;
    case ErrorCode::no_triangles: return kNoTriangles;
    case ErrorCode::canceled: return kCanceled;
    case ErrorCode::not_built: return kNotBuilt;
    case ErrorCode::internal: return kInternal;
  }
  return kInternal;
}

void check_writable_destination(const std::string& path) {
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw IoError{"cannot write " + path + ": " + std::strerror(errno)};
}

void write_file_atomically(const std::string& path, const void* data, size_t size) {
  namespace fs = std::filesystem;
  fs::path target(path);
  fs::path temp = target;
  temp += ".tmp-" + std::to_string(::getpid());
  int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError{"cannot write " + path + ": " + std::strerror(errno)};
  const char* p = static_cast<const char*>(data);
  size_t left = size;
  while (left > 0) {
    ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      std::string reason = std::strerror(errno);
      ::close(fd);
      ::unlink(temp.c_str());
      throw IoError{"cannot write " + path + ": " + reason};
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  bool synced = ::fsync(fd) == 0;
  bool closed = ::close(fd) == 0;
  if (!synced || !closed) {
    std::string reason = std::strerror(errno);
    ::unlink(temp.c_str());
    throw IoError{"cannot write " + path + ": " + reason};
  }
  if (::rename(temp.c_str(), target.c_str()) != 0) {
    std::string reason = std::strerror(errno);
    ::unlink(temp.c_str());
    throw IoError{"cannot write " + path + ": " + reason};
  }
}

const char* format_name(io::Format f) {
  switch (f) {
    case io::Format::glb: return "glb";
    case io::Format::gltf: return "gltf";
    case io::Format::drc: return "drc";
  }
  return "unknown";
}

}  // namespace soupuv::cli
