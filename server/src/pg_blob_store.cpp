// BlobStore on PostgreSQL: a blob is rows of kBlobChunkBytes (1 MiB) bytea in
// soupuv_blob_chunks plus its size in soupuv_blobs (pg_schema.cpp). Chosen
// over large objects because rows go with the job's other rows (deleted in
// the same transaction, copied by an ordinary dump, no lo_unlink to forget)
// and 1 MiB rows keep each statement's memory at one chunk.
//
// put() reads the local file a chunk at a time inside one transaction (the
// blob appears whole or not at all); read() fetches one chunk per statement
// on a pooled connection taken for that chunk only, so a slow download never
// holds a connection between pieces.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "soupuv/server/blob_store.h"
#include "soupuv/server/pg_connection.h"
#include "soupuv/server/result_blobs.h"
#include "soupuv/server/storage.h"

namespace soupuv::server {
namespace fs = std::filesystem;
namespace {

class PgBlobStore final : public BlobStore {
 public:
  explicit PgBlobStore(PgPool& pool) : pool_(pool) {}

  void put(const std::string& id, const std::string& name, const fs::path& from) override {
    int fd = ::open(from.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw std::runtime_error("open " + from.string() + ": " + std::strerror(errno));
    struct Closer {
      int fd;
      ~Closer() { ::close(fd); }
    } closer{fd};
    auto c = pool_.take();
    c->transaction([&](PgConnection& t) {
      t.exec("DELETE FROM soupuv_blob_chunks WHERE job_id = $1 AND name = $2", {id, name});
      std::string buf;
      int64_t total = 0;
      for (int n = 0;; ++n) {
        buf.resize(size_t(kBlobChunkBytes));
        size_t got = 0;
        while (got < buf.size()) {
          ssize_t r = ::read(fd, buf.data() + got, buf.size() - got);
          if (r < 0 && errno == EINTR) continue;
          if (r < 0) throw std::runtime_error("read " + from.string() + ": " + std::strerror(errno));
          if (r == 0) break;
          got += size_t(r);
        }
        if (got == 0 && n > 0) break;
        buf.resize(got);
        total += int64_t(got);
        t.exec("INSERT INTO soupuv_blob_chunks (job_id, name, n, data) VALUES ($1, $2, $3, $4)",
               {id, name, pg_int(n), PgParam::bytes(buf)});
        if (got < size_t(kBlobChunkBytes)) break;
      }
      t.exec("INSERT INTO soupuv_blobs (job_id, name, bytes) VALUES ($1, $2, $3)"
             " ON CONFLICT (job_id, name) DO UPDATE SET bytes = EXCLUDED.bytes, created_at = now()",
             {id, name, pg_int(total)});
    });
    std::error_code ec;
    fs::remove(from, ec);  // consumed, as put() allows: the local copy is scratch
  }

  std::optional<int64_t> size(const std::string& id, const std::string& name) override {
    auto c = pool_.take();
    auto r = c->exec("SELECT bytes FROM soupuv_blobs WHERE job_id = $1 AND name = $2", {id, name});
    if (r.rows() == 0) return std::nullopt;
    return r.integer(0, 0);
  }

  bool read(const std::string& id, const std::string& name, int64_t offset, int64_t length,
            const std::function<bool(const char*, size_t)>& sink) override {
    if (!size(id, name)) return false;
    while (length > 0) {
      const int64_t n = offset / kBlobChunkBytes, skip = offset % kBlobChunkBytes;
      std::string data;
      {
        auto c = pool_.take();
        auto r = c->exec("SELECT data FROM soupuv_blob_chunks WHERE job_id = $1 AND name = $2 AND n = $3",
                         {id, name, pg_int(n)}, /*binary_result=*/true);
        if (r.rows() == 0) return false;  // deleted under the reader (TTL, DELETE)
        data.assign(PQgetvalue(r.get(), 0, 0), size_t(PQgetlength(r.get(), 0, 0)));
      }
      if (skip >= int64_t(data.size())) return false;
      const size_t take = size_t(std::min<int64_t>(length, int64_t(data.size()) - skip));
      if (!sink(data.data() + skip, take)) return false;
      offset += int64_t(take);
      length -= int64_t(take);
    }
    return true;
  }

  std::vector<std::string> names(const std::string& id) override {
    auto c = pool_.take();
    auto r = c->exec("SELECT name FROM soupuv_blobs WHERE job_id = $1 ORDER BY name", {id});
    std::vector<std::string> out;
    for (int i = 0; i < r.rows(); ++i) out.push_back(r.text(i, 0));
    return out;
  }

  void remove(const std::string& id) override {
    auto c = pool_.take();
    c->transaction([&](PgConnection& t) {
      t.exec("DELETE FROM soupuv_blob_chunks WHERE job_id = $1", {id});
      t.exec("DELETE FROM soupuv_blobs WHERE job_id = $1", {id});
    });
  }

  void remove_attempt(const std::string& id, int attempt) override {
    // starts_with, not LIKE: a prefix, never a pattern.
    const std::string prefix = attempt_prefix(attempt);
    auto c = pool_.take();
    c->transaction([&](PgConnection& t) {
      t.exec("DELETE FROM soupuv_blob_chunks WHERE job_id = $1 AND starts_with(name, $2)", {id, prefix});
      t.exec("DELETE FROM soupuv_blobs WHERE job_id = $1 AND starts_with(name, $2)", {id, prefix});
    });
  }

 private:
  PgPool& pool_;
};

}  // namespace

std::unique_ptr<BlobStore> open_pg_blob_store(PgPool& pool) { return std::make_unique<PgBlobStore>(pool); }

}  // namespace soupuv::server
