// BlobStore over the data directory, the embedded default's layout:
// DATA/jobs/<id>/<name> (results: DATA/jobs/<id>/attempt-<n>/<name>,
// result_blobs.h). put() is the fsync + rename the scheduler has
// always used to commit results (a reader sees a whole file or none).
#include <fstream>

#include "soupuv/server/blob_store.h"
#include "soupuv/server/files.h"
#include "soupuv/server/result_blobs.h"

namespace soupuv::server {
namespace fs = std::filesystem;
namespace {

class FileBlobStore final : public BlobStore {
 public:
  explicit FileBlobStore(const DataDir& data) : data_(data) {}

  void put(const std::string& id, const std::string& name, const fs::path& from) override {
    const fs::path to = data_.job(id) / name;
    // attempt-<n>/, a folder upload's subfolders: a new directory's entry is
    // fsynced too, or a power loss could lose the blob commit_file made durable.
    if (fs::create_directories(to.parent_path())) fsync_path(to.parent_path().parent_path());
    commit_file(from, to);
  }

  std::optional<int64_t> size(const std::string& id, const std::string& name) override {
    std::error_code ec;
    auto n = fs::file_size(data_.job(id) / name, ec);
    if (ec) return std::nullopt;
    return int64_t(n);
  }

  bool read(const std::string& id, const std::string& name, int64_t offset, int64_t length,
            const std::function<bool(const char*, size_t)>& sink) override {
    std::ifstream in(data_.job(id) / name, std::ios::binary);
    if (!in) return false;
    in.seekg(std::streamoff(offset));
    std::vector<char> buf(size_t(std::min<int64_t>(length, 65536)) + 1);
    while (length > 0) {
      in.read(buf.data(), std::streamsize(std::min<int64_t>(length, int64_t(buf.size()))));
      const auto got = int64_t(in.gcount());
      if (got <= 0) return false;
      if (!sink(buf.data(), size_t(got))) return false;
      length -= got;
    }
    return true;
  }

  std::vector<std::string> names(const std::string& id) override {
    std::vector<std::string> out;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(data_.job(id), ec))
      if (e.is_regular_file()) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }

  void remove(const std::string& id) override {
    std::error_code ec;
    fs::remove_all(data_.job(id), ec);
  }

  void remove_attempt(const std::string& id, int attempt) override {
    // attempt-<n>/ is a directory of its own: its blobs go with it.
    fs::remove_all((data_.job(id) / attempt_prefix(attempt)).parent_path());
  }

 private:
  const DataDir& data_;
};

}  // namespace

std::unique_ptr<BlobStore> open_file_blob_store(const DataDir& data) {
  return std::make_unique<FileBlobStore>(data);
}

}  // namespace soupuv::server
