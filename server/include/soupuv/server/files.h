// Data-directory layout and durable file operations. Paths are only ever built
// from validated job ids and fixed file names, never from request text.
//
//   DATA/jobs.sqlite           job metadata (SqliteJobStore)
//   DATA/jobs/<id>/input.glb   the upload (input.gltf, input.drc), texture.png|jpg
//   DATA/jobs/<id>/result.glb  diagnostics.json  uv-layout.png  proxy.glb  field-lines.glb
//   DATA/cache/                the pipeline's content-addressed field cache
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace soupuv::server {

// 128 random bits (getrandom) as 26 lowercase base32 characters, prefixed "j".
std::string new_job_id();
bool is_valid_job_id(std::string_view id);

class DataDir {
 public:
  explicit DataDir(std::filesystem::path root);
  const std::filesystem::path& root() const { return root_; }
  std::filesystem::path database() const { return root_ / "jobs.sqlite"; }
  std::filesystem::path cache() const { return root_ / "cache"; }
  std::filesystem::path uploads_tmp() const { return root_ / "tmp"; }
  // Requires is_valid_job_id(id).
  std::filesystem::path job(const std::string& id) const;

 private:
  std::filesystem::path root_;
};

// Writes `bytes` to `path` via a temp file in the same directory, fsync, rename,
// then fsyncs the directory, so a reader sees the old file or the whole new one.
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);
// fsync a file, rename it over `to`, fsync the directory.
void commit_file(const std::filesystem::path& from, const std::filesystem::path& to);
void fsync_path(const std::filesystem::path& path);
std::string read_file(const std::filesystem::path& path, int64_t max_bytes);

// Streams bytes to a file with a hard byte budget; the caller renames on success.
// A full disk or quota throws StorageUnavailable (storage.h), other I/O errors
// std::runtime_error.
class BoundedFileWriter {
 public:
  BoundedFileWriter(const std::filesystem::path& path, int64_t budget);
  ~BoundedFileWriter();
  // False once the budget would be exceeded (nothing more is written).
  bool write(const char* data, size_t n);
  void finish();  // fsync + close; throws on I/O error
  int64_t bytes() const { return bytes_; }
  bool over_budget() const { return over_; }

 private:
  int fd_ = -1;
  std::filesystem::path path_;
  int64_t budget_, bytes_ = 0;
  bool over_ = false;
};

}  // namespace soupuv::server
