// Where a job's files live: its input (input.glb|gltf|drc, texture.png|jpg)
// and its results (result.glb, diagnostics.json, ..., stored per attempt:
// result_blobs.h). The embedded default
// is the data directory (FileBlobStore: DATA/jobs/<id>/<name>, what it has
// always been); with --database-url they are chunked bytea rows in
// PostgreSQL (PgBlobStore), so every node serves every job's files.
//
// Files move in pieces both ways: put() reads a local file and get()/read()
// deliver pieces, so no file is ever whole in memory on either side.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace soupuv::server {

class DataDir;
class PgPool;

class BlobStore {
 public:
  virtual ~BlobStore() = default;
  // Stores the local file `from` as `name` of job `id`, replacing an older
  // one; durable when it returns. The file may be moved (consumed) by the
  // store: callers do not use `from` afterwards.
  virtual void put(const std::string& id, const std::string& name, const std::filesystem::path& from) = 0;
  virtual std::optional<int64_t> size(const std::string& id, const std::string& name) = 0;
  // Delivers bytes [offset, offset + length) in pieces to `sink` (false
  // from the sink stops); false if the blob does not exist.
  virtual bool read(const std::string& id, const std::string& name, int64_t offset, int64_t length,
                    const std::function<bool(const char*, size_t)>& sink) = 0;
  // Writes the blob to the local file `to` (fsynced, renamed into place).
  // False if it does not exist.
  virtual bool get(const std::string& id, const std::string& name, const std::filesystem::path& to);
  virtual std::vector<std::string> names(const std::string& id) = 0;
  virtual void remove(const std::string& id) = 0;  // every blob of the job
  // Every blob of one attempt's results (named attempt_blob(attempt, ...),
  // result_blobs.h), the other blobs of the job untouched.
  virtual void remove_attempt(const std::string& id, int attempt) = 0;
};

// Piece size of reads and of PgBlobStore rows.
inline constexpr int64_t kBlobChunkBytes = 1 << 20;

std::unique_ptr<BlobStore> open_file_blob_store(const DataDir& data);
// Tables made by the PostgreSQL migrations (pg_schema.cpp).
std::unique_ptr<BlobStore> open_pg_blob_store(PgPool& pool);

}  // namespace soupuv::server
