// The data directory's health as the API sees it: free space, writability,
// and the one error type for "the disk or the job store cannot take a write
// right now" (full disk, SQLite I/O error). Such a condition is the server's
// and usually passes (the sweeper frees space, an operator grows the volume),
// so the API answers it 503 + Retry-After, never 500, and the supervisor turns
// it into a retry or a job failure, never std::terminate.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace soupuv::server {

class StorageUnavailable : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bytes an unprivileged writer may still use on the file system holding
// `path` (statvfs f_bavail); -1 if it cannot be read.
int64_t free_bytes(const std::filesystem::path& path);

struct StorageStatus {
  bool writable = false;  // the directory accepts a new file
  bool enough_space = false;  // free_bytes >= the configured minimum
  int64_t free = -1;
};
// Probes `dir` (creates and removes a small file) and its free space.
StorageStatus storage_status(const std::filesystem::path& dir, int64_t min_free_bytes);

// Removes temp files a killed process left behind (older than `min_age`):
// the field cache's "*.tmp.<pid>.<n>" half-written entries and the server's
// own "*.tmp" files in job directories. Returns how many were removed.
int sweep_stale_temp_files(const std::filesystem::path& data_root, std::chrono::seconds min_age);

}  // namespace soupuv::server
