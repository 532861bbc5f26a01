// Unit tests of the server library's pure parts: config, job ids, params ->
// flags, auth, header guards, container checks, metrics text, the SQLite store.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "harness.h"
#include "soupuv/server/auth.h"
#include "soupuv/server/config.h"
#include "soupuv/server/files.h"
#include "soupuv/server/http_guards.h"
#include "soupuv/server/job_store.h"
#include "soupuv/server/metrics.h"
#include "soupuv/server/params.h"
#include "soupuv/server/upload_check.h"

using namespace soupuv::server;
namespace fs = std::filesystem;

namespace {
EnvLookup env_of(std::map<std::string, std::string> m) {
  return [m](const std::string& k) -> std::optional<std::string> {
    auto it = m.find(k);
    if (it == m.end()) return std::nullopt;
    return it->second;
  };
}
}  // namespace

TEST(Config, FlagsOverrideEnvOverrideDefaults) {
  Config d = parse_config({}, env_of({}));
  EXPECT_EQ(d.host, "127.0.0.1");
  EXPECT_EQ(d.port, 8080);
  Config e = parse_config({}, env_of({{"SOUPUV_PORT", "9000"}, {"SOUPUV_WORKERS", "3"}, {"SOUPUV_CORS_ORIGINS", "http://a,http://b"}}));
  EXPECT_EQ(e.port, 9000);
  EXPECT_EQ(e.workers, 3);
  EXPECT_EQ(e.cors_origins, (std::vector<std::string>{"http://a", "http://b"}));
  Config f = parse_config({"--port", "9100", "--queue-capacity=7", "--tokens-file", "/t"}, env_of({{"SOUPUV_PORT", "9000"}}));
  EXPECT_EQ(f.port, 9100);
  EXPECT_EQ(f.queue_capacity, 7);
  EXPECT_EQ(f.tokens_file, "/t");
}

TEST(Config, RejectsBadValuesAndUnknownFlags) {
  EXPECT_THROW(parse_config({"--port", "70000"}, env_of({})), ConfigError);
  EXPECT_THROW(parse_config({"--workers", "two"}, env_of({})), ConfigError);
  EXPECT_THROW(parse_config({"--nope", "1"}, env_of({})), ConfigError);
  EXPECT_THROW(parse_config({"--port"}, env_of({})), ConfigError);
  EXPECT_THROW(parse_config({}, env_of({{"SOUPUV_PORT", "x"}})), ConfigError);
}

TEST(Config, HelpNamesTheContractFlags) {
  std::string h = help_text();
  for (const char* f : {"--host", "--port", "--data-dir", "--workers", "--queue-capacity", "--tokens-file", "SOUPUV_HOST"})
    EXPECT_NE(h.find(f), std::string::npos) << f;
}

TEST(Config, ThreadsAreDividedBetweenWorkers) {
  Config c = parse_config({"--threads", "8", "--workers", "3"}, env_of({}));
  EXPECT_EQ(c.threads_per_job(), 2);
  c = parse_config({"--threads", "2", "--workers", "4"}, env_of({}));
  EXPECT_EQ(c.threads_per_job(), 1);
}

TEST(JobId, RandomAndValidated) {
  std::set<std::string> seen;
  for (int i = 0; i < 1000; ++i) {
    std::string id = new_job_id();
    EXPECT_TRUE(is_valid_job_id(id)) << id;
    seen.insert(id);
  }
  EXPECT_EQ(seen.size(), 1000u);
  for (const char* bad : {"", "j", "../../etc/passwd", "jAAAAAAAAAAAAAAAAAAAAAAAAAA", "x234567abcdefghijklmnopqrst",
                          "j234567abcdefghijklmnopqrs/", "j1234567abcdefghijklmnopqr"})
    EXPECT_FALSE(is_valid_job_id(bad)) << bad;
}

TEST(Params, ValidatesAndMapsToFlags) {
  WorkerCapabilities caps;
  caps.flags = {"--method", "--texture-size", "--draco"};
  nlohmann::json out;
  EXPECT_FALSE(validate_params({{"method", "box"}, {"texture_size", 512}, {"draco", true}}, caps, out));
  auto flags = params_to_flags(out, caps);
  EXPECT_EQ(flags, (std::vector<std::string>{"--method", "box", "--texture-size", "512", "--draco"}));
  EXPECT_TRUE(validate_params({{"method", "magic"}}, caps, out));
  EXPECT_TRUE(validate_params({{"texture_size", 3}}, caps, out));
  EXPECT_TRUE(validate_params({{"texture_size", 500}}, caps, out));  // not a power of two
  EXPECT_TRUE(validate_params({{"texture_size", "big"}}, caps, out));
  EXPECT_TRUE(validate_params({{"whatever", 1}}, caps, out));
  EXPECT_TRUE(validate_params(nlohmann::json::array(), caps, out));
  caps.flags.insert("--charge-iterations");
  EXPECT_FALSE(validate_params({{"charge_iterations", 60}}, caps, out));
  EXPECT_EQ(params_to_flags(out, caps), (std::vector<std::string>{"--method", "field", "--charge-iterations", "60"}));
  EXPECT_TRUE(validate_params({{"charge_iterations", 0}}, caps, out));
  // Known to the API but not to this CLI build: refused, not silently dropped.
  auto e = validate_params({{"steps", 100}}, caps, out);
  ASSERT_TRUE(e);
  EXPECT_NE(e.detail.find("not supported"), std::string::npos);
}

TEST(Auth, ConstantTimeCompareAndBearerParsing) {
  EXPECT_TRUE(constant_time_equal("abc", "abc"));
  EXPECT_FALSE(constant_time_equal("abc", "abd"));
  EXPECT_FALSE(constant_time_equal("abc", "abcd"));
  EXPECT_FALSE(constant_time_equal("", "a"));
  EXPECT_EQ(TokenSet::bearer("Bearer xyz"), "xyz");
  EXPECT_EQ(TokenSet::bearer("bearer xyz"), "xyz");  // the scheme is case-insensitive (RFC 9110 11.1)
  EXPECT_EQ(TokenSet::bearer("BEARER  xyz "), "xyz");
  EXPECT_EQ(TokenSet::bearer("Basic xyz"), "");
  EXPECT_EQ(TokenSet::bearer("Bearerxyz"), "");
  EXPECT_EQ(TokenSet::bearer("Bearer "), "");
  EXPECT_EQ(TokenSet::bearer("Bearer a b"), "");
}

TEST(Auth, TokensFileNamesTenantsAndRefusesWeakTokens) {
  const std::string a(32, 'a'), b = std::string(40, 'b'), c = "c" + std::string(35, '7');
  fs::path dir = soupuv::test::fresh_dir("tokens");
  std::ofstream(dir / "t") << "# comment\n\nalice " << a << "\n  bob\t" << b << "  \r\n" << c << "\n";
  TokenSet t = TokenSet::load((dir / "t").string());
  EXPECT_EQ(t.size(), 3u);
  EXPECT_EQ(t.tenant_for(a), "alice");
  EXPECT_EQ(t.tenant_for(b), "bob");
  // A token alone is its own tenant, named by a hash, never by the token.
  auto own = t.tenant_for(c);
  ASSERT_TRUE(own);
  EXPECT_EQ(own->rfind("token-", 0), 0u);
  EXPECT_EQ(own->size(), 6u + 16u);
  EXPECT_EQ(own->find(c.substr(0, 8)), std::string::npos);
  EXPECT_FALSE(t.tenant_for(a.substr(0, 31)));
  EXPECT_FALSE(t.tenant_for(""));
  auto refused = [&](const std::string& text) {
    std::ofstream(dir / "bad") << text;
    try {
      TokenSet::load((dir / "bad").string());
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refused("# nothing\n").find("no tokens"), std::string::npos);
  EXPECT_NE(refused("alice short-token\n").find("line 1: token shorter than 32 bytes"), std::string::npos);
  EXPECT_NE(refused(a + "\nbob " + a + "\n").find("line 2: token listed twice"), std::string::npos);
  EXPECT_NE(refused("al/ice " + a + "\n").find("tenant"), std::string::npos);
  EXPECT_NE(refused("x y " + a + "\n").find("TENANT TOKEN"), std::string::npos);
}

TEST(Guards, RefuseBeforeTheBody) {
  auto req = [](std::string method, std::string path, httplib::Headers h) {
    httplib::Request r;
    r.method = method;
    r.path = path;
    r.headers = h;
    return r;
  };
  const int64_t max = 1000;
  auto status = [&](const httplib::Request& r) {
    auto v = check_request_headers(r, max);
    return v ? v->status : 0;
  };
  EXPECT_EQ(status(req("GET", "/v1/jobs", {})), 0);
  EXPECT_EQ(status(req("POST", "/v1/jobs", {{"Content-Type", "model/gltf-binary"}, {"Content-Length", "10"}})), 0);
  EXPECT_EQ(status(req("POST", "/v1/jobs", {{"Content-Type", "model/gltf-binary"}})), 411);
  EXPECT_EQ(status(req("POST", "/v1/jobs", {{"Content-Type", "model/gltf-binary"}, {"Content-Length", "1"}, {"Content-Length", "1"}})), 411);
  EXPECT_EQ(status(req("POST", "/v1/jobs", {{"Content-Type", "model/gltf-binary"}, {"Content-Length", "-1"}})), 411);
  EXPECT_EQ(status(req("POST", "/v1/jobs", {{"Content-Type", "model/gltf-binary"}, {"Content-Length", "1001"}})), 413);
  EXPECT_EQ(status(req("POST", "/v1/jobs", {{"Content-Type", "text/plain"}, {"Content-Length", "1"}})), 415);
  EXPECT_EQ(status(req("POST", "/v1/jobs", {{"Content-Type", "model/gltf-binary"}, {"Content-Length", "1"}, {"Content-Encoding", "gzip"}})), 415);
  EXPECT_EQ(status(req("POST", "/v1/jobs", {{"Content-Type", "model/gltf-binary"}, {"Transfer-Encoding", "chunked"}})), 411);
  EXPECT_EQ(status(req("GET", "/" + std::string(2000, 'a'), {})), 414);
  EXPECT_EQ(status(req("POST", "/healthz", {{"Content-Length", "1"}})), 405);
  EXPECT_EQ(media_type(" Multipart/Form-Data ; boundary=x"), "multipart/form-data");
}

TEST(UploadCheck, ContainerChecksOnSharedBadFiles) {
  auto check = [](const std::string& rel, ModelKind k) {
    return check_model_file(soupuv::test::shared_data(rel), k);
  };
  EXPECT_TRUE(check("gltf/Box.glb", ModelKind::glb).ok);
  EXPECT_TRUE(check("drc/test_nm.drc", ModelKind::draco).ok);
  EXPECT_FALSE(check("bad/empty.glb", ModelKind::glb).ok);
  EXPECT_FALSE(check("bad/length-lie.glb", ModelKind::glb).ok);
  EXPECT_FALSE(check("bad/truncated.glb", ModelKind::glb).ok);
  EXPECT_FALSE(check("bad/not-gltf.gltf", ModelKind::gltf).ok);
  auto ext = check("bad/external-uri.gltf", ModelKind::gltf);
  EXPECT_FALSE(ext.ok);
  EXPECT_EQ(ext.slug, "external-uri");
  EXPECT_FALSE(check("gltf/Box.glb", ModelKind::draco).ok);  // wrong kind
}

TEST(Metrics, PrometheusTextHasHistogramsAndCounters) {
  Metrics m;
  m.http_request(200);
  m.http_request(429);
  m.stage_seconds("load", 0.2);
  m.stage_seconds("load", 7);
  std::string t = m.render({{"queue_depth", 3}, {"jobs:queued", 3}});
  EXPECT_NE(t.find("soupuv_http_requests_total{code=\"429\"} 1"), std::string::npos);
  EXPECT_NE(t.find("soupuv_stage_duration_seconds_bucket{stage=\"load\",le=\"0.5\"} 1"), std::string::npos);
  EXPECT_NE(t.find("soupuv_stage_duration_seconds_bucket{stage=\"load\",le=\"10\"} 2"), std::string::npos);
  EXPECT_NE(t.find("soupuv_stage_duration_seconds_count{stage=\"load\"} 2"), std::string::npos);
  EXPECT_NE(t.find("soupuv_queue_depth 3"), std::string::npos);
  EXPECT_NE(t.find("soupuv_jobs{state=\"queued\"} 3"), std::string::npos);
  m.http_duration("status", 0.0003);
  m.http_duration("status", 0.02);
  t = m.render({});
  EXPECT_NE(t.find("soupuv_http_request_duration_seconds_bucket{route=\"status\",le=\"0.0005\"} 1"), std::string::npos) << t;
  EXPECT_NE(t.find("soupuv_http_request_duration_seconds_bucket{route=\"status\",le=\"0.025\"} 2"), std::string::npos) << t;
  EXPECT_NE(t.find("soupuv_http_request_duration_seconds_count{route=\"status\"} 2"), std::string::npos) << t;
}

TEST(SqliteJobStore, LifecyclePagingIdempotencyAndPersistence) {
  fs::path dir = soupuv::test::fresh_dir("store");
  std::string db = (dir / "jobs.sqlite").string();
  std::vector<std::string> ids;
  {
    auto store = open_sqlite_job_store(db);
    for (int i = 0; i < 5; ++i) {
      Job j;
      j.id = new_job_id();
      j.created_at = now_seconds();
      j.input_file = "input.glb";
      j.content_type = "model/gltf-binary";
      j.request_hash = "h" + std::to_string(i);
      if (i == 0) j.idempotency_key = "key-0";
      auto stored = store->create_or_get_by_key(j);
      ASSERT_TRUE(stored);
      EXPECT_EQ(stored->id, j.id);
      ids.push_back(j.id);
    }
    Job dup;
    dup.id = new_job_id();
    dup.idempotency_key = "key-0";
    dup.request_hash = "other";
    auto existing = store->create_or_get_by_key(dup);
    ASSERT_TRUE(existing);
    EXPECT_EQ(existing->id, ids[0]);
    EXPECT_EQ(existing->request_hash, "h0");

    store->mark_running(ids[1], now_seconds());
    store->update_progress(ids[1], "load", 0.5, {{"parse", 0.1}});
    store->finish(ids[2], JobState::failed, JobError{"invalid_input", 400, "bad"}, {}, 0, now_seconds() - 100);
    store->finish(ids[3], JobState::succeeded, std::nullopt, {"result.glb"}, 1, now_seconds());

    auto p1 = store->list(std::nullopt, 2, "", std::nullopt);
    ASSERT_EQ(p1.jobs.size(), 2u);
    EXPECT_EQ(p1.jobs[0].id, ids[4]);  // newest first
    EXPECT_FALSE(p1.next_cursor.empty());
    auto p2 = store->list(std::nullopt, 2, p1.next_cursor, std::nullopt);
    ASSERT_EQ(p2.jobs.size(), 2u);
    EXPECT_EQ(p2.jobs[0].id, ids[2]);
    auto p3 = store->list(std::nullopt, 2, p2.next_cursor, std::nullopt);
    ASSERT_EQ(p3.jobs.size(), 1u);
    EXPECT_TRUE(p3.next_cursor.empty());
    auto failed = store->list(JobState::failed, 10, "", std::nullopt);
    ASSERT_EQ(failed.jobs.size(), 1u);
    EXPECT_EQ(failed.jobs[0].error->detail, "bad");
    EXPECT_EQ(store->count_by_state()["queued"], 2);
  }
  // Reopen: everything is still there (what restart recovery relies on).
  auto store = open_sqlite_job_store(db);
  auto running = store->get(ids[1]);
  ASSERT_TRUE(running);
  EXPECT_EQ(running->state, JobState::running);
  EXPECT_EQ(running->stage, "load");
  EXPECT_EQ(running->attempts, 1);
  auto un = store->unfinished();
  ASSERT_EQ(un.size(), 3u);
  EXPECT_EQ(un[0].id, ids[0]);  // oldest first: FIFO survives restarts
  EXPECT_EQ(un[1].id, ids[1]);
  auto old = store->finished_before(now_seconds() - 50);
  EXPECT_EQ(old, std::vector<std::string>{ids[2]});
  store->remove(ids[2]);
  EXPECT_FALSE(store->get(ids[2]));
  auto ok = store->get(ids[3]);
  EXPECT_EQ(ok->outputs, std::vector<std::string>{"result.glb"});
}

TEST(Files, AtomicWriteAndBoundedWriter) {
  fs::path dir = soupuv::test::fresh_dir("files");
  write_file_atomic(dir / "a.txt", "hello");
  EXPECT_EQ(soupuv::test::read_bytes(dir / "a.txt"), "hello");
  EXPECT_FALSE(fs::exists(dir / "a.txt.tmp"));
  BoundedFileWriter w(dir / "b", 10);
  EXPECT_TRUE(w.write("12345", 5));
  EXPECT_FALSE(w.write("123456", 6));
  EXPECT_TRUE(w.over_budget());
  w.finish();
  EXPECT_EQ(fs::file_size(dir / "b"), 5u);
}

namespace {
int64_t peak_rss_kib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoll(line.substr(6));
  return -1;
}
}  // namespace

// The glTF JSON of an upload is attacker text parsed inside the server: it is
// scanned (SAX), not built into a document, and its nesting is capped.
TEST(UploadCheck, JsonIsScannedNotBuiltAndNestingIsCapped) {
  fs::path dir = soupuv::test::fresh_dir("json-scan");
  {
    // 40 MB of tiny elements: as a DOM (16+ bytes each, vectors doubling) this
    // is several hundred MB; a scan needs almost nothing.
    std::string text = R"({"asset":{"version":"2.0"},"extras":[)";
    text.reserve(40 << 20);
    while (text.size() < (40u << 20)) text += "0,";
    text += R"(0],"buffers":[{"uri":"data:application/octet-stream;base64,AAAA"}]})";
    std::ofstream(dir / "flat.gltf") << text;
  }
  const int64_t before = peak_rss_kib();
  EXPECT_TRUE(check_model_file(dir / "flat.gltf", ModelKind::gltf).ok);
  EXPECT_LT(peak_rss_kib() - before, 64 * 1024) << "KiB of peak RSS added by the check";

  std::ofstream(dir / "deep.gltf") << R"({"extras":)" << std::string(100000, '[') << std::string(100000, ']') << "}";
  auto deep = check_model_file(dir / "deep.gltf", ModelKind::gltf);
  EXPECT_FALSE(deep.ok);
  EXPECT_NE(deep.detail.find("nested too deeply"), std::string::npos) << deep.detail;
  // The checks themselves are unchanged: external URIs, non-object roots, lists.
  std::ofstream(dir / "ext.gltf") << R"({"images":[{"uri":"https://example.com/x.png"}]})";
  EXPECT_EQ(check_model_file(dir / "ext.gltf", ModelKind::gltf).slug, "external-uri");
  std::ofstream(dir / "uri-num.gltf") << R"({"buffers":[{"uri":{"nested":1}}]})";
  EXPECT_EQ(check_model_file(dir / "uri-num.gltf", ModelKind::gltf).slug, "external-uri");
  std::ofstream(dir / "root.gltf") << R"([1,2])";
  EXPECT_FALSE(check_model_file(dir / "root.gltf", ModelKind::gltf).ok);
  std::ofstream(dir / "list.gltf") << R"({"buffers":{"uri":"data:,"}})";
  EXPECT_NE(check_model_file(dir / "list.gltf", ModelKind::gltf).detail.find("must be an array"), std::string::npos);
  std::ofstream(dir / "broken.gltf") << R"({"buffers":[)";
  EXPECT_NE(check_model_file(dir / "broken.gltf", ModelKind::gltf).detail.find("does not parse"), std::string::npos);
}
