// API details (issue 21, item 7): cancel is its own action and DELETE only
// deletes; Retry-After on 202 and on polls of unfinished jobs; an opaque list
// cursor; Allow on 405; problem types the server serves under /problems/;
// metrics with HELP on every metric, full-precision sums, escaped labels and
// soupuv_build_info.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>

#include "harness.h"
#include "soupuv/server/metrics.h"
#include "soupuv/server/problem.h"

using namespace soupuv::test;
using nlohmann::json;
namespace fs = std::filesystem;

TEST(ApiDetails, CancelIsItsOwnActionAndDeleteOnlyDeletes) {
  auto s = with_double("cancel-action", "slow", {"--workers", "1"});
  auto c = s->client();
  const std::string id = submit_box(c);
  ASSERT_FALSE(id.empty());
  ASSERT_EQ(wait_state(c, id, "running")["state"], "running");
  // DELETE of a running job neither cancels nor deletes it.
  auto del = c.Delete(("/v1/jobs/" + id).c_str());
  ASSERT_TRUE(del);
  EXPECT_EQ(del->status, 409);
  EXPECT_EQ(json::parse(del->body)["type"], "/problems/job-not-finished");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(json::parse(c.Get(("/v1/jobs/" + id).c_str())->body)["state"], "running");
  auto cancel = c.Post(("/v1/jobs/" + id + ":cancel").c_str());
  ASSERT_TRUE(cancel);
  EXPECT_EQ(cancel->status, 202) << cancel->body;
  EXPECT_EQ(wait_state(c, id, "canceled", 10)["state"], "canceled");
  // A retried cancel changes nothing and says so; the record stays.
  auto again = c.Post(("/v1/jobs/" + id + ":cancel").c_str());
  EXPECT_EQ(again->status, 200);
  EXPECT_EQ(json::parse(again->body)["state"], "canceled");
  EXPECT_EQ(c.Get(("/v1/jobs/" + id).c_str())->status, 200);
  // Deleting is explicit, once.
  EXPECT_EQ(c.Delete(("/v1/jobs/" + id).c_str())->status, 204);
  EXPECT_EQ(c.Delete(("/v1/jobs/" + id).c_str())->status, 404);
  // Canceling a finished job is a conflict, not a silent success.
  auto s2 = with_double("cancel-finished", "slow", {}, "0");
  auto c2 = s2->client();
  const std::string done = submit_box(c2);
  ASSERT_EQ(wait_finished(c2, done, 20)["state"], "succeeded");
  EXPECT_EQ(c2.Post(("/v1/jobs/" + done + ":cancel").c_str())->status, 409);
}

TEST(ApiDetails, RetryAfterOnAcceptedAndOnPollsOfUnfinishedJobs) {
  auto s = with_double("retry-after", "slow", {"--workers", "1"}, "2");
  auto c = s->client();
  auto r = submit(c, read_bytes(shared_data("gltf/Box.glb")), "model/gltf-binary");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202);
  EXPECT_FALSE(r->get_header_value("Retry-After").empty());
  const std::string id = json::parse(r->body)["id"];
  ASSERT_EQ(wait_state(c, id, "running")["state"], "running");
  auto running = c.Get(("/v1/jobs/" + id).c_str());
  EXPECT_EQ(running->get_header_value("Retry-After"), "1");
  ASSERT_EQ(wait_finished(c, id, 20)["state"], "succeeded");
  EXPECT_FALSE(c.Get(("/v1/jobs/" + id).c_str())->has_header("Retry-After"));
}

TEST(ApiDetails, ListCursorIsOpaque) {
  auto s = with_double("cursor", "slow", {}, "0");
  auto c = s->client();
  std::set<std::string> ids;
  for (int i = 0; i < 3; ++i) ids.insert(submit_box(c));
  std::set<std::string> seen;
  std::string cursor;
  for (int page = 0; page < 5; ++page) {
    auto r = c.Get(("/v1/jobs?limit=1" + (cursor.empty() ? "" : "&cursor=" + cursor)).c_str());
    ASSERT_EQ(r->status, 200) << r->body;
    auto j = json::parse(r->body);
    for (const auto& job : j["jobs"]) seen.insert(job["id"].get<std::string>());
    if (j["next_cursor"].is_null()) break;
    cursor = j["next_cursor"];
    // Not the store's sequence number in clear.
    EXPECT_FALSE(std::all_of(cursor.begin(), cursor.end(), ::isdigit)) << cursor;
  }
  EXPECT_EQ(seen, ids);
  for (const char* forged : {"3", "abc", "Yz", "c1:3"}) {
    auto r = c.Get((std::string("/v1/jobs?cursor=") + forged).c_str());
    EXPECT_EQ(r->status, 400) << forged;
  }
}

TEST(ApiDetails, MethodNotAllowedNamesTheAllowedMethods) {
  auto s = with_double("allow", "slow", {}, "0");
  auto c = s->client();
  auto put = c.Put("/v1/jobs", "", "application/json");
  ASSERT_TRUE(put);
  EXPECT_EQ(put->status, 405);
  EXPECT_EQ(put->get_header_value("Allow"), "GET, POST");
  EXPECT_EQ(put->get_header_value("Content-Type"), "application/problem+json");
  auto del = c.Delete("/v1/params");
  EXPECT_EQ(del->status, 405);
  EXPECT_EQ(del->get_header_value("Allow"), "GET");
  auto body = c.Post("/healthz", "x", "text/plain");
  EXPECT_EQ(body->status, 405);
  EXPECT_EQ(body->get_header_value("Allow"), "GET");
  // A path that exists for this method but not this id is still 404.
  EXPECT_EQ(c.Get("/v1/jobs/not-an-id")->status, 404);
}

TEST(ApiDetails, ProblemTypesAreServedByTheServer) {
  auto s = with_double("problems", "slow", {}, "0");
  auto c = s->client();
  auto missing = c.Get("/v1/jobs/jaaaaaaaaaaaaaaaaaaaaaaaaaa");
  const std::string type = json::parse(missing->body)["type"];
  EXPECT_EQ(type, "/problems/not-found");
  for (const auto& t : soupuv::server::problem_types()) {
    auto page = c.Get((std::string("/problems/") + t.slug).c_str());
    ASSERT_TRUE(page);
    EXPECT_EQ(page->status, 200) << t.slug;
    EXPECT_NE(page->body.find(t.meaning), std::string::npos) << t.slug;
  }
  EXPECT_EQ(c.Get("/problems/no-such-problem")->status, 404);
}

TEST(ApiDetails, EverySlugTheServerUsesIsAServedProblemType) {
  // Every literal slug given to set_problem / Rejection / UploadVerdict in
  // server/src must be in problem_types() (else its `type` would be about:blank).
  const std::regex use(R"re((set_problem\(res, [^";\n]*|Rejection\{[0-9]+, |\{false, )"([a-z][a-z-]+)")re");
  int found = 0;
  for (const auto& e : fs::directory_iterator(fs::path(SOUPUV_SOURCE_DIR) / "server" / "src")) {
    const std::string text = read_bytes(e.path());
    for (std::sregex_iterator it(text.begin(), text.end(), use), end; it != end; ++it) {
      ++found;
      EXPECT_NE(soupuv::server::find_problem_type((*it)[2]), nullptr)
          << (*it)[2] << " in " << e.path().filename() << " is not in problem_types()";
    }
  }
  EXPECT_GT(found, 20);
}

TEST(Metrics, HelpOnEveryMetricFullPrecisionEscapedLabelsBuildInfo) {
  soupuv::server::Metrics m;
  m.stage_seconds("proxy", 1234.56789012345);
  m.stage_seconds("we\"ird\\stage\nname", 1);
  m.job_finished("succeeded");
  m.http_request(200);
  const std::string text = m.render({{"queue_depth", 3}, {"jobs:queued", 2}, {"workers", 1}});
  std::set<std::string> typed, helped;
  std::regex type_re("# TYPE (\\S+) "), help_re("# HELP (\\S+) ");
  for (std::sregex_iterator it(text.begin(), text.end(), type_re), end; it != end; ++it) typed.insert((*it)[1]);
  for (std::sregex_iterator it(text.begin(), text.end(), help_re), end; it != end; ++it) helped.insert((*it)[1]);
  EXPECT_EQ(typed, helped) << text;
  EXPECT_TRUE(typed.count("soupuv_queue_depth"));
  EXPECT_NE(text.find("soupuv_stage_duration_seconds_sum{stage=\"proxy\"} 1234.56789012345"), std::string::npos)
      << text;
  EXPECT_NE(text.find("stage=\"we\\\"ird\\\\stage\\nname\""), std::string::npos) << text;
  EXPECT_NE(text.find("soupuv_build_info{version=\""), std::string::npos);
}
