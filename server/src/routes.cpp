// Every HTTP route of soupuv-server, in one file: the API v1 job routes, the
// operational endpoints (/healthz /readyz /metrics), the OpenAPI document and
// the upload page. Cross-cutting guards (headers checked before a body is read,
// auth, CORS, problem+json for every error) are installed here too.
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

#include "soupuv/hash.h"
#include "soupuv/openmp_wait.h"
#include "soupuv/server/app.h"
#include "soupuv/server/http_guards.h"
#include "soupuv/server/http_server.h"
#include "soupuv/server/list_cursor.h"
#include "soupuv/server/log.h"
#include "soupuv/server/problem.h"
#include "soupuv/server/result_blobs.h"
#include "soupuv/server/sandbox.h"
#include "soupuv/server/storage.h"
#include "soupuv/server/upload_check.h"
#include "soupuv/server/upload_folder.h"
#include "soupuv/server/worker_process.h"

namespace soupuv::server {
namespace fs = std::filesystem;

const std::vector<RouteInfo>& api_routes() {
  static const std::vector<RouteInfo> routes = {
      {"post", "/v1/jobs"},
      {"get", "/v1/jobs"},
      {"get", "/v1/jobs/{id}"},
      {"delete", "/v1/jobs/{id}"},
      {"post", "/v1/jobs/{id}:cancel"},
      {"get", "/v1/jobs/{id}/result"},
      {"get", "/v1/jobs/{id}/diagnostics"},
      {"get", "/v1/jobs/{id}/uv-layout.png"},
      {"get", "/v1/jobs/{id}/proxy.glb"},
      {"get", "/v1/jobs/{id}/field-lines.glb"},
      {"get", "/v1/params"},
      {"get", "/v1/openapi.yaml"},
      {"get", "/healthz"},
      {"get", "/readyz"},
      {"get", "/metrics"},
      {"get", "/problems/{slug}"},
  };
  return routes;
}

namespace {

constexpr int64_t kMaxParamsBytes = 64 << 10;
constexpr size_t kMaxMetadataBytes = 4096;  // a job's opaque metadata object, as compact JSON
const char* const kJobIdPattern = "(j[a-z2-7]{26})";

int retry_after_seconds(const ServerContext& ctx) {
  // Rough: one queue's worth of work per worker, a few seconds each; clients
  // only need a sensible back-off, not a promise.
  size_t depth = ctx.scheduler->queue_depth();
  return int(std::clamp<size_t>(depth / size_t(std::max(1, ctx.config.workers)), 1, 60));
}

void queue_full(httplib::Response& res, const ServerContext& ctx, int status) {
  res.set_header("Retry-After", std::to_string(retry_after_seconds(ctx)));
  set_problem(res, status, status == 429 ? "queue-full" : "unavailable",
              status == 429 ? "the job queue is full; retry after the indicated seconds"
                            : "the server is not accepting jobs right now");
}

// A client polling a job should come back when something may have changed:
// soon for a running job, after about the queue's drain time for a queued one.
void poll_hint(httplib::Response& res, const ServerContext& ctx, const Job& job) {
  if (job.state == JobState::running) res.set_header("Retry-After", "1");
  else if (job.state == JobState::queued) res.set_header("Retry-After", std::to_string(retry_after_seconds(ctx)));
}

// Methods the API serves on `path` (from api_routes()), for Allow on 405.
std::set<std::string> methods_for(const std::string& path) {
  // The route table as (regex, METHOD), compiled once.
  static const std::vector<std::pair<std::regex, std::string>> routes = [] {
    std::vector<std::pair<std::regex, std::string>> out;
    for (const auto& r : api_routes()) {
      std::string m = r.method;
      std::transform(m.begin(), m.end(), m.begin(), ::toupper);
      out.emplace_back(std::regex(std::regex_replace(r.path, std::regex("\\{[a-z]+\\}"), "[^/:]+")), m);
    }
    return out;
  }();
  std::set<std::string> methods;
  for (const auto& [re, m] : routes)
    if (std::regex_match(path, re)) methods.insert(m);
  return methods;
}

std::string allowed_methods(const std::string& path) {
  std::string out;
  for (const auto& m : methods_for(path)) out += (out.empty() ? "" : ", ") + m;
  return out;
}

void send_json(httplib::Response& res, int status, const nlohmann::json& j) {
  res.status = status;
  res.set_content(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), "application/json");
}

// Streams a stored file in pieces (never loaded whole): at most one chunk
// (blob_store.h) per call of the provider, from disk or from PostgreSQL.
bool send_blob(httplib::Response& res, BlobStore& blobs, const std::string& id, const std::string& name,
               const std::string& type) {
  auto size = blobs.size(id, name);
  if (!size) return false;
  res.set_content_provider(
      size_t(*size), type,
      [&blobs, id, name](size_t offset, size_t length, httplib::DataSink& sink) {
        const int64_t n = std::min<int64_t>(int64_t(length), kBlobChunkBytes - int64_t(offset) % kBlobChunkBytes);
        return blobs.read(id, name, int64_t(offset), n,
                          [&](const char* p, size_t len) { return sink.write(p, len); });
      });
  return true;
}

// The tenant a request acts for: "" without tokens; nullopt when tokens are
// configured and this request's token is not (any more: a SIGHUP between the
// guard and the handler) accepted, which then sees nothing.
std::optional<std::string> request_tenant(const ServerContext& ctx, const httplib::Request& req) {
  auto tokens = ctx.tokens.get();
  if (!tokens->enabled()) return std::string();
  return tokens->tenant_for(TokenSet::bearer(req.get_header_value("Authorization")));
}

// Another tenant's job is answered exactly like a missing one: its existence
// is not revealed.
std::optional<Job> job_or_404(ServerContext& ctx, const httplib::Request& req, httplib::Response& res) {
  const std::string id = req.matches[1];
  auto job = is_valid_job_id(id) ? ctx.store->get(id) : std::nullopt;
  auto tenant = request_tenant(ctx, req);
  if (job && (!tenant || job->tenant != *tenant)) job.reset();
  if (!job) set_problem(res, 404, "not-found", "no such job");
  return job;
}

// Query parameters -> params JSON: `params=<json>` and/or one key per parameter
// (numbers, booleans and arrays parsed, anything else a string).
std::optional<nlohmann::json> params_from_query(const httplib::Request& req, std::string& error) {
  nlohmann::json p = nlohmann::json::object();
  if (req.has_param("params")) {
    p = nlohmann::json::parse(req.get_param_value("params"), nullptr, false);
    if (!p.is_object()) {
      error = "query parameter 'params' must be a JSON object";
      return std::nullopt;
    }
  }
  for (const auto& [k, v] : req.params) {
    if (k == "params") continue;
    auto parsed = nlohmann::json::parse(v, nullptr, false);
    p[k] = (parsed.is_number() || parsed.is_boolean() || parsed.is_array()) ? parsed : nlohmann::json(v);
  }
  return p;
}

bool valid_idempotency_key(const std::string& k) {
  if (k.empty() || k.size() > 128) return false;
  return std::all_of(k.begin(), k.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == ':';
  });
}

struct ValidationSlot {
  std::atomic<int>& n;
  ~ValidationSlot() { --n; }
};

// The files a worker may read for `model`: the model alone, or, for a folder
// upload, every regular file under `folder` (which holds the model).
std::vector<std::string> model_files(const fs::path& model, const fs::path& folder) {
  std::vector<std::string> files = {model.string()};
  std::error_code ec;
  if (folder.empty() || !fs::is_directory(folder, ec)) return files;
  for (auto it = fs::recursive_directory_iterator(folder, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec))
    if (it->is_regular_file(ec) && !it->is_symlink(ec) && it->path() != model) files.push_back(it->path().string());
  return files;
}

// Runs `soupuv inspect` on the upload in a child process (never in the server:
// a hostile file may crash a parser) and turns a refusal into a problem.
std::optional<Rejection> inspect_upload(ServerContext& ctx, const fs::path& file, const fs::path& folder) {
  if (!ctx.config.validate_uploads || !ctx.caps.has_inspect) return std::nullopt;
  // Bound concurrent inspections so uploads cannot starve the workers' cores.
  int limit = std::max(1, ctx.config.workers);
  while (ctx.validations_running.fetch_add(1) >= limit) {
    --ctx.validations_running;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ValidationSlot slot{ctx.validations_running};
  ProcessLimits limits;
  limits.wall_seconds = 60;
  limits.address_space_bytes = ctx.config.worker_memory_mb << 20;
  limits.cpu_seconds = 60;
  // Sandboxed like a job's worker: it reads the upload, writes nothing (its
  // scratch directory is the upload's own temp directory, read-only here).
  SandboxPaths paths;
  paths.program = ctx.worker_bin;
  paths.read_files = model_files(file, folder);
  std::string sandbox_error;
  if (!confine_worker(ctx.config, paths, file.parent_path().string(), limits, sandbox_error)) {
    log::error("worker sandbox could not be built", {{"error", sandbox_error}});
    return Rejection{503, "unavailable", "the upload cannot be checked safely right now"};
  }
  RulesetCloser closer{limits.landlock_ruleset};
  std::string reason;
  std::atomic<bool> never{false};
  auto outcome = run_process({ctx.worker_bin, "inspect", file.string()},
                             worker_environment(file.parent_path().string(), ctx.config.worker_env, {"OMP_NUM_THREADS=1", std::string("OMP_WAIT_POLICY=") + kOpenMpWaitPolicy}),
                             limits, never, [&](const std::string& line) {
                               if (line.rfind("soupuv: ", 0) == 0) reason = line.substr(8, 500);
                             });
  auto verdict = classify_outcome(outcome, reason, ctx.config);
  if (verdict.state == JobState::succeeded) return std::nullopt;
  const JobError& e = *verdict.error;
  if (e.http_status >= 500) {  // a crash or timeout in inspect: let the job decide
    log::warn("inspect failed, queueing anyway", {{"detail", e.detail}});
    return std::nullopt;
  }
  return Rejection{e.http_status, e.code == "no_triangles" ? "no-triangles" : "invalid-model", e.detail};
}

// POST /v1/jobs. Order matters: cheap refusals (queue full, bad key) before the
// body is read; the body streams to a temp directory under a byte budget; the
// directory is renamed into place only once the upload is whole and checked.
// The refusals of POST /v1/jobs that need no body: the same checks answer
// `Expect: 100-continue` (so a client is told before it sends a byte) and
// run again when the body path starts. `in_flight`: uploads in progress
// counting this one (the body path has taken its slot). True if refused.
bool refuse_submission(ServerContext& ctx, const httplib::Request& req, httplib::Response& res, int in_flight) {
  if (ctx.worker_bin.empty()) {
    set_problem(res, 503, "unavailable", "no worker binary is installed");
    return true;
  }
  if (!request_tenant(ctx, req)) {
    set_problem(res, 401, "invalid-token", "the bearer token is not accepted");
    return true;
  }
  if (!ctx.scheduler->has_room()) {
    queue_full(res, ctx, 429);
    return true;
  }
  if (in_flight > ctx.config.upload_slots()) {
    res.set_header("Retry-After", "1");
    set_problem(res, 503, "uploads-busy", "too many uploads in progress; retry after the indicated seconds");
    return true;
  }
  // A full disk is a refusal, not a failed job later: the upload, its
  // results and the job row all need room.
  // (The header guard has checked Content-Length: present, one, <= 18 digits.)
  const int64_t announced = req.has_header("Content-Length") ? std::stoll(req.get_header_value("Content-Length")) : 0;
  const int64_t free = free_bytes(ctx.data->root());
  if (free >= 0 && free - announced < (ctx.config.min_free_mb << 20)) {
    log::warn("upload refused: low disk space", {{"free_bytes", free}, {"min_free_mb", ctx.config.min_free_mb}});
    res.set_header("Retry-After", "60");
    set_problem(res, 503, "insufficient-storage", "the server is low on disk space; retry after the indicated seconds");
    return true;
  }
  if (req.has_header("Idempotency-Key") && !valid_idempotency_key(req.get_header_value("Idempotency-Key"))) {
    set_problem(res, 400, "bad-idempotency-key", "Idempotency-Key must be 1-128 characters of [A-Za-z0-9-_.:]");
    return true;
  }
  return false;
}

void replay(httplib::Response& res, const ServerContext& ctx, const Job& stored, const Job& job) {
  if (stored.request_hash != job.request_hash)
    return set_problem(res, 422, "idempotency-key-reused", "this Idempotency-Key was used with a different request");
  res.set_header("Location", "/v1/jobs/" + stored.id);
  res.set_header("Idempotent-Replayed", "true");
  poll_hint(res, ctx, stored);
  send_json(res, 202, to_json(stored));
}

// The end of POST /v1/jobs with --database-url: the checked upload's files go
// into the blob store (streamed, durable when put returns), then the row is
// inserted as queued, capacity counted across the service (JobQueue::submit),
// and every node's idle workers are woken by its NOTIFY. Blobs of a refused
// submission are deleted here; those of a node that died in between are
// swept after an hour (PgJobStore::expire).
void submit_shared(ServerContext& ctx, const httplib::Request&, httplib::Response& res, const Job& job,
                   const fs::path& tmp, int64_t model_bytes) {
  struct Undo {
    ServerContext& ctx;
    std::string id;
    ~Undo() {
      if (id.empty()) return;
      try {
        ctx.blobs->remove(id);
      } catch (const std::exception& e) {
        log::warn("blobs of a refused upload not removed (swept later)", {{"job", id}, {"error", e.what()}});
      }
    }
  } undo{ctx, job.id};
  for (const std::string name : {job.input_file, std::string("texture.png"), std::string("texture.jpg")})
    if (fs::exists(tmp / name)) ctx.blobs->put(job.id, name, tmp / name);
  // A folder upload (model/...): every file the checked folder holds, so the
  // node that runs the job finds the .gltf's buffers and images too.
  if (job.input_file.rfind("model/", 0) == 0)
    for (const auto& entry : fs::recursive_directory_iterator(tmp / "model"))
      if (entry.is_regular_file() && !entry.is_symlink() && entry.path() != tmp / job.input_file)
        ctx.blobs->put(job.id, fs::relative(entry.path(), tmp).generic_string(), entry.path());
  SubmitAnswer answer = ctx.queue->submit(job, ctx.config.queue_capacity);
  if (answer.admission == Admission::full) return queue_full(res, ctx, 429);
  if (answer.admission == Admission::duplicate) return replay(res, ctx, *answer.job, job);
  undo.id.clear();
  ctx.metrics.upload_bytes(model_bytes);
  log::info("job submitted", {{"job", job.id}, {"bytes", model_bytes}, {"type", job.content_type}, {"params", job.params}});
  res.set_header("Location", "/v1/jobs/" + job.id);
  poll_hint(res, ctx, *answer.job);
  send_json(res, 202, to_json(*answer.job));
}

void submit_job(ServerContext& ctx, const httplib::Request& req, httplib::Response& res,
                const httplib::ContentReader& content_reader) {
  // Head-of-line guard: uploads hold an HTTP thread for seconds (body, fsync,
  // inspect); capped below the pool size, polls and health checks always find
  // a free thread.
  struct UploadSlot {
    std::atomic<int>& n;
    ~UploadSlot() { --n; }
  } slot{ctx.uploads_in_flight};
  if (refuse_submission(ctx, req, res, ++ctx.uploads_in_flight)) return;
  const auto tenant = request_tenant(ctx, req);
  if (!tenant) return set_problem(res, 401, "invalid-token", "the bearer token is not accepted");
  const std::string key = req.get_header_value("Idempotency-Key");
  std::string perr;
  auto query_params = params_from_query(req, perr);
  if (!query_params) return set_problem(res, 400, "invalid-params", perr);

  const std::string id = new_job_id();
  const fs::path tmp = ctx.data->uploads_tmp() / id;
  fs::create_directories(tmp);
  struct Cleanup {
    fs::path p;
    ~Cleanup() {
      std::error_code ec;
      if (!p.empty()) fs::remove_all(p, ec);
    }
  } cleanup{tmp};

  const std::string media = media_type(req.get_header_value("Content-Type"));
  const int64_t budget = ctx.config.max_upload_bytes;
  Hasher hasher;
  std::optional<ModelKind> kind;
  std::string params_text, texture_name;
  bool too_large = false, have_model = false;
  int64_t model_bytes = 0;

  auto kind_for = [](const std::string& m) -> std::optional<ModelKind> {
    if (m == "model/gltf-binary") return ModelKind::glb;
    if (m == "model/gltf+json") return ModelKind::gltf;
    if (m == "application/octet-stream") return ModelKind::draco;
    return std::nullopt;
  };
  // A folder upload: the model plus its files ("files" parts), or a zip.
  bool zip = false;
  size_t folder_files = 0;
  const fs::path folder = tmp / "model";

  if (media == "multipart/form-data") {
    std::unique_ptr<BoundedFileWriter> writer;
    std::string part;
    int64_t total = 0;
    bool bad_part = false;
    std::string bad_detail;
    bool ok = content_reader(
        [&](const httplib::MultipartFormData& f) {
          if (writer) writer->finish();
          writer.reset();
          part = f.name;
          hasher.add(std::string_view(part));
          if (part == "file") {
            if (have_model) { bad_part = true; bad_detail = "more than one 'file' part"; return false; }
            have_model = true;
            kind = kind_for(media_type(f.content_type));
            const std::string fname = f.filename;
            auto ends_zip = fname.size() > 4 && fname.compare(fname.size() - 4, 4, ".zip") == 0;
            if (media_type(f.content_type) == "application/zip" || ends_zip) {
              zip = true;
              kind = ModelKind::glb;  // replaced by the model found in the zip
              writer = std::make_unique<BoundedFileWriter>(tmp / "upload.zip", budget);
              return true;
            }
            if (!kind || media_type(f.content_type) == "application/octet-stream") {
              // Browsers send octet-stream for unknown extensions: go by the name.
              auto ends = [&](const char* e) { return fname.size() >= strlen(e) && fname.compare(fname.size() - strlen(e), strlen(e), e) == 0; };
              if (ends(".glb")) kind = ModelKind::glb;
              else if (ends(".gltf")) kind = ModelKind::gltf;
              else if (ends(".drc")) kind = ModelKind::draco;
              else if (!kind) { bad_part = true; bad_detail = "the file part must be a .glb, .gltf or .drc"; return false; }
            }
            writer = std::make_unique<BoundedFileWriter>(tmp / file_name_for(*kind), budget);
          } else if (part == "texture") {
            std::string m = media_type(f.content_type);
            if (m != "image/png" && m != "image/jpeg") { bad_part = true; bad_detail = "texture must be image/png or image/jpeg"; return false; }
            texture_name = m == "image/png" ? "texture.png" : "texture.jpg";
            writer = std::make_unique<BoundedFileWriter>(tmp / texture_name, budget);
          } else if (part == "files") {
            // One file the model names, at its relative path (the part's filename).
            if (auto why = unsafe_relative_path(f.filename); !why.empty()) {
              bad_part = true;
              bad_detail = "files part: " + why;
              return false;
            }
            if (++folder_files > kMaxFolderEntries) {
              bad_part = true;
              bad_detail = "more than " + std::to_string(kMaxFolderEntries) + " 'files' parts";
              return false;
            }
            const fs::path target = folder / f.filename;
            std::error_code ec;
            fs::create_directories(target.parent_path(), ec);
            if (ec || fs::exists(target)) {
              bad_part = true;
              bad_detail = "files part '" + f.filename.substr(0, 80) + "' is named twice or clashes with a folder";
              return false;
            }
            writer = std::make_unique<BoundedFileWriter>(target, budget);
          } else if (part != "params") {
            bad_part = true;
            bad_detail = "unknown form part '" + part.substr(0, 40) + "' (expected file, files, params, texture)";
            return false;
          }
          return true;
        },
        [&](const char* data, size_t n) {
          total += int64_t(n);
          if (total > budget) { too_large = true; return false; }
          hasher.add_bytes(data, n);
          if (part == "params") {
            if (int64_t(params_text.size() + n) > kMaxParamsBytes) { bad_part = true; bad_detail = "params part larger than 64 KiB"; return false; }
            params_text.append(data, n);
            return true;
          }
          if (!writer) return false;
          if (part == "file" || part == "files") model_bytes += int64_t(n);
          return writer->write(data, n);
        });
    if (writer) writer->finish();
    if (too_large) return set_problem(res, 413, "too-large", "upload exceeds the byte limit");
    if (bad_part) return set_problem(res, 400, "invalid-form", bad_detail);
    if (!ok) return set_problem(res, 400, "invalid-form", "the multipart body could not be read");
    if (!have_model) return set_problem(res, 400, "invalid-form", "multipart body needs a 'file' part");
  } else {
    kind = kind_for(media);
    if (media == "application/zip") {
      zip = true;
      kind = ModelKind::glb;  // replaced by the model found in the zip
    }
    BoundedFileWriter writer(tmp / "body", budget);
    char sniff[5] = {};
    size_t sniffed = 0;
    bool ok = content_reader([&](const char* data, size_t n) {
      for (size_t i = 0; i < n && sniffed < 5; ++i) sniff[sniffed++] = data[i];
      hasher.add_bytes(data, n);
      if (!writer.write(data, n)) { too_large = true; return false; }
      return true;
    });
    writer.finish();
    if (too_large) return set_problem(res, 413, "too-large", "upload exceeds the byte limit");
    if (!ok) return set_problem(res, 400, "incomplete-body", "the request body could not be read whole");
    // application/octet-stream is Draco, but a GLB sent as octet-stream is recognised.
    if (*kind == ModelKind::draco && sniffed >= 4 && std::memcmp(sniff, "glTF", 4) == 0) kind = ModelKind::glb;
    model_bytes = writer.bytes();
    fs::rename(tmp / "body", zip ? tmp / "upload.zip" : tmp / file_name_for(*kind));
  }

  // Where the model is, relative to the job directory.
  std::string input_file = file_name_for(*kind);
  if (zip) {
    if (folder_files) return set_problem(res, 400, "invalid-form", "send either a .zip or 'files' parts, not both");
    std::string found;
    if (auto r = unpack_zip(tmp / "upload.zip", folder, uint64_t(budget), found))
      return set_problem(res, r->status, r->slug, r->detail);
    fs::remove(tmp / "upload.zip");
    kind = found.size() > 4 && found.compare(found.size() - 4, 4, ".glb") == 0 ? ModelKind::glb : ModelKind::gltf;
    input_file = "model/" + found;
    std::error_code ec;
    model_bytes = 0;
    for (auto it = fs::recursive_directory_iterator(folder, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec))
      if (it->is_regular_file(ec)) model_bytes += int64_t(it->file_size(ec));
  } else if (folder_files) {
    if (*kind == ModelKind::draco)
      return set_problem(res, 400, "invalid-form", "'files' parts go with a .gltf (a .drc names no files)");
    // The model joins its files; a files part of the same name is a clash.
    const fs::path target = folder / file_name_for(*kind);
    if (fs::exists(target))
      return set_problem(res, 400, "invalid-form", std::string("a files part may not be named ") + file_name_for(*kind));
    fs::rename(tmp / file_name_for(*kind), target);
    input_file = std::string("model/") + file_name_for(*kind);
  }

  nlohmann::json raw_params = *query_params;
  if (!params_text.empty()) {
    auto p = nlohmann::json::parse(params_text, nullptr, false);
    if (!p.is_object()) return set_problem(res, 400, "invalid-params", "the params part must be a JSON object");
    for (auto it = p.begin(); it != p.end(); ++it) raw_params[it.key()] = it.value();
  }
  // The caller's own fields, stored in params (every job store persists
  // params) but never turned into worker flags: an opaque metadata object
  // and the job-end callback URL.
  nlohmann::json own = nlohmann::json::object();
  for (const char* key : {"metadata", "callback_url"}) {
    if (!raw_params.contains(key)) continue;
    own[key] = raw_params[key];
    raw_params.erase(key);
  }
  if (own.contains("metadata")) {
    nlohmann::json& m = own["metadata"];
    if (m.is_string()) m = nlohmann::json::parse(m.get<std::string>(), nullptr, false);  // from a query string
    if (!m.is_object()) return set_problem(res, 400, "invalid-params", "metadata must be a JSON object");
    if (m.dump().size() > kMaxMetadataBytes)
      return set_problem(res, 413, "metadata-too-large",
                         "metadata is " + std::to_string(m.dump().size()) + " bytes as JSON, more than " +
                             std::to_string(kMaxMetadataBytes));
  }
  if (own.contains("callback_url")) {
    if (!own["callback_url"].is_string()) return set_problem(res, 400, "invalid-params", "callback_url must be a string");
    if (auto why = check_callback_url(own["callback_url"].get<std::string>()); !why.empty())
      return set_problem(res, 400, "invalid-params", why);
    if (!ctx.callbacks)
      return set_problem(res, 400, "invalid-params", "this server sends no callbacks (it has no --callback-secret)");
  }
  nlohmann::json params;
  if (auto e = validate_params(raw_params, ctx.caps, params)) return set_problem(res, 400, "invalid-params", e.detail);
  for (auto it = own.begin(); it != own.end(); ++it) params[it.key()] = it.value();
  hasher.add(std::string_view(params.dump()));

  const fs::path model = tmp / input_file;
  UploadVerdict check = check_model_file(model, *kind, zip || folder_files > 0);
  if (!check.ok) return set_problem(res, 400, check.slug, check.detail);
  if (auto r = inspect_upload(ctx, model, zip || folder_files ? folder : fs::path()))
    return set_problem(res, r->status, r->slug, r->detail);

  Job job;
  job.id = id;
  job.created_at = now_seconds();
  job.params = params;
  job.input_file = input_file;
  job.content_type = *kind == ModelKind::glb ? "model/gltf-binary" : *kind == ModelKind::gltf ? "model/gltf+json" : "application/octet-stream";
  job.input_bytes = model_bytes;
  job.tenant = *tenant;
  job.idempotency_key = key;
  job.request_hash = hasher.hex();

  if (ctx.queue) return submit_shared(ctx, req, res, job, tmp, model_bytes);

  // Durable before visible: files are fsynced by BoundedFileWriter, the
  // directory rename is atomic, then the row is committed.
  const fs::path dir = ctx.data->job(id);
  fs::rename(tmp, dir);
  cleanup.p = dir;  // until the job is committed below
  fsync_path(dir.parent_path());
  auto stored = ctx.store->create_or_get_by_key(job);
  if (!stored) return set_problem(res, 500, "internal", "job could not be stored");
  if (stored->id != id) {  // Idempotency-Key already used
    if (stored->request_hash != job.request_hash)
      return set_problem(res, 422, "idempotency-key-reused", "this Idempotency-Key was used with a different request");
    res.set_header("Location", "/v1/jobs/" + stored->id);
    res.set_header("Idempotent-Replayed", "true");
    poll_hint(res, ctx, *stored);
    return send_json(res, 202, to_json(*stored));
  }
  auto queued = ctx.scheduler->enqueue(id);
  if (queued != Scheduler::Enqueue::accepted) {
    ctx.store->remove(id);
    return queue_full(res, ctx, queued == Scheduler::Enqueue::full ? 429 : 503);
  }
  cleanup.p.clear();
  ctx.metrics.upload_bytes(model_bytes);
  log::info("job submitted", {{"job", id}, {"bytes", model_bytes}, {"type", job.content_type}, {"params", params}});
  res.set_header("Location", "/v1/jobs/" + id);
  poll_hint(res, ctx, *stored);
  send_json(res, 202, to_json(*stored));
}

void serve_output(ServerContext& ctx, const httplib::Request& req, httplib::Response& res, const std::string& name,
                  const std::string& type) {
  auto job = job_or_404(ctx, req, res);
  if (!job) return;
  if (job->state != JobState::succeeded) {
    nlohmann::json extra = {{"state", to_string(job->state)}};
    if (job->error) extra["job_error"] = {{"code", job->error->code}, {"detail", job->error->detail}};
    return set_problem(res, 409, "not-finished",
                       job->state == JobState::failed ? "the job failed: " + (job->error ? job->error->detail : "")
                                                      : std::string("the job is ") + to_string(job->state),
                       extra);
  }
  // The blob of the attempt the outcome names, never another attempt's
  // (a late writer's) under the same file name (result_blobs.h).
  if (std::find(job->outputs.begin(), job->outputs.end(), name) == job->outputs.end() ||
      !send_blob(res, *ctx.blobs, job->id, result_blob(*job, name), type))
    return set_problem(res, 404, "not-found", "this job has no " + name);
  res.status = 200;
  if (name == "result.glb") res.set_header("Content-Disposition", "attachment; filename=\"" + job->id + ".glb\"");
}

// Per connection thread: when the request being served entered routing.
thread_local std::optional<std::chrono::steady_clock::time_point> t_request_started;

std::string route_class(const httplib::Request& req) {
  if (req.path == "/healthz" || req.path == "/readyz") return req.path.substr(1);
  if (req.method == "GET" && req.path.size() == 36 && req.path.rfind("/v1/jobs/", 0) == 0) return "status";
  return "other";
}

bool cors_allowed(const ServerContext& ctx, const std::string& origin) {
  return !origin.empty() && std::find(ctx.config.cors_origins.begin(), ctx.config.cors_origins.end(), origin) !=
                                ctx.config.cors_origins.end();
}

}  // namespace

std::string render_metrics(ServerContext& ctx) {
  std::map<std::string, double> gauges;
  for (const auto& [state, n] : ctx.store->count_by_state()) gauges["jobs:" + state] = double(n);
  gauges["queue_depth"] = double(ctx.scheduler->queue_depth());
  gauges["queue_capacity"] = ctx.config.queue_capacity;
  gauges["workers_busy"] = ctx.scheduler->busy_workers();
  gauges["workers"] = ctx.config.workers;
  return ctx.metrics.render(gauges);
}

void register_routes(httplib::Server& http, ServerContext& ctx) {
  // ---- guards -------------------------------------------------------------
  auto guard = [&ctx](const httplib::Request& req, httplib::Response& res) -> bool {
    if (auto r = check_request_headers(req, ctx.config.max_upload_bytes)) {
      if (r->status == 405) res.set_header("Allow", allowed_methods(req.path));
      set_problem(res, r->status, r->slug, r->detail);
      // The body (if any) is unread: the connection cannot carry another request.
      close_connection_after(res);
      return false;
    }
    // Tokens guard the API and /metrics (jobs by state, queue depth: not for
    // everyone; --metrics-port serves it without a token on its own address).
    // Health checks, the OpenAPI document, CORS preflights and the upload page stay open.
    auto tokens = ctx.tokens.get();
    const bool protected_path = (req.path.rfind("/v1/", 0) == 0 && req.path != "/v1/openapi.yaml") ||
                                req.path == "/metrics";
    if (tokens->enabled() && protected_path && req.method != "OPTIONS") {
      // RFC 6750 §3: no credentials -> a bare challenge; bad ones -> invalid_token.
      if (!req.has_header("Authorization")) {
        res.set_header("WWW-Authenticate", "Bearer realm=\"soupuv\"");
        set_problem(res, 401, "unauthorized", "a bearer token is required");
        close_connection_after(res);
        return false;
      }
      if (!tokens->accepts(TokenSet::bearer(req.get_header_value("Authorization")))) {
        res.set_header("WWW-Authenticate",
                       "Bearer realm=\"soupuv\", error=\"invalid_token\", error_description=\"the token is not accepted\"");
        set_problem(res, 401, "invalid-token", "the bearer token is not accepted");
        close_connection_after(res);
        return false;
      }
    }
    return true;
  };
  http.set_expect_100_continue_handler([&ctx, guard](const httplib::Request& req, httplib::Response& res) {
    // The body path's own refusals too (queue, slots, disk): a client that
    // asked first must not upload a body only to hear 429 after it.
    const bool submit = req.method == "POST" && req.path == "/v1/jobs";
    if (guard(req, res) && !(submit && refuse_submission(ctx, req, res, ctx.uploads_in_flight.load() + 1))) return 100;
    close_connection_after(res);
    // 0.11.4 writes this early answer without Content-Length and keeps the
    // connection open, so a client would wait for the close while uploading
    // its body; with the length it reads the answer and stops sending.
    res.set_header("Content-Length", std::to_string(res.body.size()));
    return res.status;
  });
  http.set_pre_routing_handler([&ctx, guard](const httplib::Request& req, httplib::Response& res) {
    t_request_started = std::chrono::steady_clock::now();
    const std::string origin = req.get_header_value("Origin");
    if (cors_allowed(ctx, origin)) {
      res.set_header("Access-Control-Allow-Origin", origin);
      res.set_header("Vary", "Origin");
      res.set_header("Access-Control-Expose-Headers", "Location, Retry-After");
    }
    if (req.method == "OPTIONS") {  // CORS preflight: answered here, nothing else
      // A preflight has no body; if one is announced it stays unread.
      if (req.has_header("Content-Length") || req.has_header("Transfer-Encoding")) close_connection_after(res);
      if (cors_allowed(ctx, origin)) {
        res.set_header("Access-Control-Allow-Methods", "GET, POST, DELETE, OPTIONS");
        res.set_header("Access-Control-Allow-Headers", "Authorization, Content-Type, Idempotency-Key");
        res.set_header("Access-Control-Max-Age", "600");
      }
      res.status = 204;
      return httplib::Server::HandlerResponse::Handled;
    }
    return guard(req, res) ? httplib::Server::HandlerResponse::Unhandled : httplib::Server::HandlerResponse::Handled;
  });
  // 0.11.4 puts e.what() into a response header without a handler; ours logs
  // it and answers a plain problem.
  http.set_exception_handler([](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "unknown";
    bool unavailable = false;
    try {
      std::rethrow_exception(ep);
    } catch (const StorageUnavailable& e) {
      what = e.what();
      unavailable = true;
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    log::error("request failed", {{"method", req.method}, {"path", req.path.substr(0, 200)}, {"error", what}});
    close_connection_after(res);
    if (unavailable) {  // full disk, failing job store: the client should come back
      res.set_header("Retry-After", "30");
      return set_problem(res, 503, "storage-unavailable", "the server cannot store data right now; retry after the indicated seconds");
    }
    set_problem(res, 500, "internal", "internal server error");
  });
  // Errors httplib produces itself (unknown route, 400 on a bad request line,
  // 413 from its payload cap) get a problem body too.
  http.set_error_handler(httplib::Server::HandlerWithResponse([](const httplib::Request& req, httplib::Response& res) {
    close_connection_after(res);  // e.g. a 404 on a POST whose body nobody read
    if (!res.body.empty() || res.is_chunked_content_provider_) return httplib::Server::HandlerResponse::Unhandled;
    // The router says 404 for a known path with another method: that is 405 + Allow.
    if (res.status == 404) {
      const auto methods = methods_for(req.path);
      if (!methods.empty() && !methods.count(req.method)) {
        const std::string allow = allowed_methods(req.path);
        res.set_header("Allow", allow);
        set_problem(res, 405, "method-not-allowed", req.method.substr(0, 10) + " is not served here; see Allow");
        return httplib::Server::HandlerResponse::Handled;
      }
    }
    std::string slug = res.status == 404 ? "not-found" : res.status == 413 ? "too-large" : "bad-request";
    set_problem(res, res.status, slug, status_title(res.status));
    return httplib::Server::HandlerResponse::Handled;
  }));
  http.set_logger([&ctx](const httplib::Request& req, const httplib::Response& res) {
    ctx.metrics.http_request(res.status);
    if (t_request_started) {  // unset when httplib answered before routing (bad request line)
      ctx.metrics.http_duration(route_class(req),
                                std::chrono::duration<double>(std::chrono::steady_clock::now() - *t_request_started).count());
      t_request_started.reset();
    }
    if (req.path == "/healthz" || req.path == "/readyz" || req.path == "/metrics") return;
    // Status polls are the bulk of the traffic and say nothing new; failures still log.
    if (req.method == "GET" && res.status == 200 && req.path.size() == 36 && req.path.rfind("/v1/jobs/", 0) == 0) return;
    // Never raw header values: method, a bounded path, status only.
    log::info("http", {{"method", req.method.substr(0, 10)}, {"path", req.path.substr(0, 200)}, {"status", res.status}});
  });

  // ---- API v1 -------------------------------------------------------------
  http.Post("/v1/jobs", [&ctx](const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader) {
    submit_job(ctx, req, res, reader);
    // Only an accepted upload was read to its end; any refusal may leave body
    // bytes on the connection, which must never be parsed as a request.
    if (res.status != 202) close_connection_after(res);
  });
  http.Get("/v1/jobs", [&ctx](const httplib::Request& req, httplib::Response& res) {
    std::optional<JobState> state;
    if (req.has_param("state")) {
      state = parse_job_state(req.get_param_value("state"));
      if (!state) return set_problem(res, 400, "invalid-query", "state must be queued, running, succeeded, failed or canceled");
    }
    int limit = 20;
    if (req.has_param("limit")) {
      const std::string v = req.get_param_value("limit");
      if (v.empty() || v.size() > 3 || !std::all_of(v.begin(), v.end(), ::isdigit) || std::stoi(v) < 1 || std::stoi(v) > 100)
        return set_problem(res, 400, "invalid-query", "limit must be an integer in [1, 100]");
      limit = std::stoi(v);
    }
    auto cursor = decode_list_cursor(req.has_param("cursor") ? req.get_param_value("cursor") : "");
    if (!cursor) return set_problem(res, 400, "invalid-query", "cursor must come from next_cursor");
    auto tenant = request_tenant(ctx, req);
    if (!tenant) return set_problem(res, 401, "invalid-token", "the bearer token is not accepted");
    auto page = ctx.store->list(state, limit, *cursor, *tenant);
    nlohmann::json out = {{"jobs", nlohmann::json::array()},
                          {"next_cursor", page.next_cursor.empty() ? nlohmann::json() : nlohmann::json(encode_list_cursor(page.next_cursor))}};
    for (const auto& j : page.jobs) out["jobs"].push_back(to_json(j));
    send_json(res, 200, out);
  });
  const std::string job = std::string("/v1/jobs/") + kJobIdPattern;
  http.Get(job, [&ctx](const httplib::Request& req, httplib::Response& res) {
    if (auto j = job_or_404(ctx, req, res)) {
      poll_hint(res, ctx, *j);
      send_json(res, 200, to_json(*j));
    }
  });
  // Cancel is its own action, so that DELETE only ever deletes: a retried
  // DELETE can no longer remove the record of a job it meant to cancel.
  http.Post(job + ":cancel", [&ctx](const httplib::Request& req, httplib::Response& res) {
    auto j = job_or_404(ctx, req, res);
    if (!j) return;
    if (j->state == JobState::canceled) return send_json(res, 200, to_json(*j));  // a retry: already done
    if (is_finished(j->state))
      return set_problem(res, 409, "job-finished", std::string("the job already ") + to_string(j->state),
                         {{"state", to_string(j->state)}});
    ctx.store->request_cancel(j->id);
    ctx.scheduler->cancel(j->id);
    log::info("job cancel requested", {{"job", j->id}});
    auto now = ctx.store->get(j->id);
    send_json(res, now && now->state == JobState::canceled ? 200 : 202, to_json(now ? *now : *j));
  });
  http.Delete(job, [&ctx](const httplib::Request& req, httplib::Response& res) {
    auto j = job_or_404(ctx, req, res);
    if (!j) return;
    if (!is_finished(j->state))
      return set_problem(res, 409, "job-not-finished",
                         "the job is " + std::string(to_string(j->state)) + "; cancel it first: POST /v1/jobs/" +
                             j->id + ":cancel",
                         {{"state", to_string(j->state)}});
    ctx.blobs->remove(j->id);
    ctx.store->remove(j->id);
    log::info("job deleted", {{"job", j->id}});
    res.status = 204;
  });
  http.Get(job + "/result", [&ctx](const httplib::Request& req, httplib::Response& res) {
    serve_output(ctx, req, res, "result.glb", "model/gltf-binary");
  });
  http.Get(job + "/diagnostics", [&ctx](const httplib::Request& req, httplib::Response& res) {
    serve_output(ctx, req, res, "diagnostics.json", "application/json");
  });
  http.Get(job + "/uv-layout.png", [&ctx](const httplib::Request& req, httplib::Response& res) {
    serve_output(ctx, req, res, "uv-layout.png", "image/png");
  });
  http.Get(job + "/proxy.glb", [&ctx](const httplib::Request& req, httplib::Response& res) {
    serve_output(ctx, req, res, "proxy.glb", "model/gltf-binary");
  });
  http.Get(job + "/field-lines.glb", [&ctx](const httplib::Request& req, httplib::Response& res) {
    serve_output(ctx, req, res, "field-lines.glb", "model/gltf-binary");
  });
  http.Get("/v1/params", [&ctx](const httplib::Request&, httplib::Response& res) {
    send_json(res, 200, {{"params", describe_params(ctx.caps)}, {"max_upload_bytes", ctx.config.max_upload_bytes}});
  });
  http.Get("/v1/openapi.yaml", [&ctx](const httplib::Request&, httplib::Response& res) {
    if (ctx.openapi_yaml.empty()) return set_problem(res, 404, "not-found", "openapi.yaml is not installed");
    res.set_content(ctx.openapi_yaml, "application/yaml");
  });

  // ---- operations ---------------------------------------------------------
  http.Get("/healthz", [](const httplib::Request&, httplib::Response& res) {
    res.set_content("{\"status\":\"ok\"}", "application/json");
  });
  http.Get("/readyz", [&ctx](const httplib::Request&, httplib::Response& res) {
    const StorageStatus disk = storage_status(ctx.data->root(), ctx.config.min_free_mb << 20);
    // An empty probe (the worker's capabilities --json unreadable) would run every job
    // without progress, cache or parameters: not ready, rather than silently degraded.
    nlohmann::json checks = {{"worker_binary", !ctx.worker_bin.empty()},
                             {"worker_capabilities", !ctx.caps.flags.empty()},
                             {"data_dir_writable", disk.writable},
                             {"disk_space", disk.enough_space},
                             {"queue_has_room", false}};
    try {
      checks["queue_has_room"] = ctx.scheduler->has_room();
    } catch (const std::exception&) {  // the shared queue's database is away: reported below
    }
    bool ok = checks["worker_binary"].get<bool>() && !ctx.caps.flags.empty() && disk.writable && disk.enough_space;
    if (ctx.queue) {  // --database-url: a node that cannot reach the database serves nothing useful
      bool db = false;
      try {
        ctx.queue->queued();
        db = true;
      } catch (const std::exception&) {
      }
      checks["database"] = db;
      ok = ok && db;
    }
    send_json(res, ok ? 200 : 503, {{"status", ok ? "ready" : "not ready"}, {"checks", checks}});
  });
  http.Get("/metrics", [&ctx](const httplib::Request&, httplib::Response& res) {
    res.set_content(render_metrics(ctx), "text/plain; version=0.0.4");
  });

  // ---- problem types (the `type` of every problem+json answer) -------------
  http.Get("/problems/([a-z-]+)", [](const httplib::Request& req, httplib::Response& res) {
    const ProblemType* t = find_problem_type(req.matches[1]);
    if (!t) return set_problem(res, 404, "not-found", "no such problem type");
    // Static text from the table only: nothing from the request is echoed.
    res.set_content(std::string("<!doctype html><html lang=\"en\"><meta charset=\"utf-8\"><title>") + t->title +
                        "</title><h1>" + t->title + "</h1><p>" + t->meaning + "</p><p>Problem type <code>/problems/" +
                        t->slug + "</code> of the soupuv API (RFC 9457). The answer's <code>detail</code> says what "
                                  "happened to this request.</p></html>\n",
                    "text/html; charset=utf-8");
  });

  // ---- upload page ----------------------------------------------------------
  http.Get("/(|assets/.*)", [&ctx](const httplib::Request& req, httplib::Response& res) {
    auto it = ctx.web.find(req.path);
    if (it == ctx.web.end()) return set_problem(res, 404, "not-found", "no such page");
    res.set_header("Cache-Control", "no-cache");
    res.set_content(it->second.bytes, it->second.content_type);
  });
}

}  // namespace soupuv::server
