// Folder uploads end to end with the real CLI as worker: a .gltf plus the files
// it names as multipart "files" parts, or a .zip of the folder; the job maps
// (and re-bakes the folder's base-colour texture). Refusals as problem+json:
// a file name climbing out, a .gltf naming files not sent, zip entries that
// climb out, a zip bomb, a zip without a model.
#include <gtest/gtest.h>
#include <zip.h>

#include <string>
#include <vector>

#include "harness.h"

using namespace soupuv::test;
using nlohmann::json;

namespace {

// A zip of (name, bytes) entries, built in memory with libzip.
std::string make_zip(const std::vector<std::pair<std::string, std::string>>& entries) {
  const std::filesystem::path path = fresh_dir("folder-zip") / "upload.zip";
  int err = 0;
  zip_t* z = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &err);
  EXPECT_NE(z, nullptr);
  for (const auto& [name, bytes] : entries) {
    zip_source_t* src = zip_source_buffer(z, bytes.data(), bytes.size(), 0);
    EXPECT_GE(zip_file_add(z, name.c_str(), src, ZIP_FL_ENC_UTF_8), 0) << zip_strerror(z);
  }
  EXPECT_EQ(zip_close(z), 0);
  return read_bytes(path);
}

void expect_problem(const httplib::Result& r, int status, const std::string& detail_part) {
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
  EXPECT_NE(json::parse(r->body, nullptr, false).value("detail", "").find(detail_part), std::string::npos) << r->body;
}

class FolderUpload : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!cli_available()) GTEST_SKIP() << "the soupuv CLI was not built; end-to-end tests need it";
    server_ = std::make_unique<ServerProcess>(fresh_dir("folder-upload"), std::vector<std::string>{
        "--worker-bin", SOUPUV_CLI_BIN, "--workers", "1", "--threads", "2"});
  }
  json finished(httplib::Client& c, const httplib::Result& r) {
    EXPECT_TRUE(r);
    if (!r) return nullptr;
    EXPECT_EQ(r->status, 202) << r->body;
    return wait_finished(c, json::parse(r->body)["id"], 120);
  }
  std::unique_ptr<ServerProcess> server_;
};

TEST_F(FolderUpload, GltfWithItsFilesAsParts) {
  auto c = server_->client();
  httplib::MultipartFormDataItems items = two_sided_plane_parts(R"({"method":"box","texture_size":128})");
  json done = finished(c, c.Post("/v1/jobs", items));
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  auto d = c.Get(("/v1/jobs/" + done["id"].get<std::string>() + "/diagnostics").c_str());
  ASSERT_TRUE(d);
  json diag = json::parse(d->body);
  EXPECT_EQ(diag["output"]["texture"]["source"], "rebake") << d->body;
  EXPECT_EQ(diag["soup"]["triangles"], 2);
  // rebake: false keeps the UV-check texture.
  items.back().content = R"({"method":"box","texture_size":128,"rebake":false})";
  done = finished(c, c.Post("/v1/jobs", items));
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  d = c.Get(("/v1/jobs/" + done["id"].get<std::string>() + "/diagnostics").c_str());
  ASSERT_TRUE(d);
  EXPECT_EQ(json::parse(d->body)["output"]["texture"]["source"], "uv_check") << d->body;
}

TEST_F(FolderUpload, ZipOfTheFolder) {
  auto c = server_->client();
  const std::string dir = shared_data("gltf/TwoSidedPlane/");
  const std::string zip = make_zip({{"plane/TwoSidedPlane.gltf", read_bytes(dir + "TwoSidedPlane.gltf")},
                                    {"plane/TwoSidedPlane.bin", read_bytes(dir + "TwoSidedPlane.bin")},
                                    {"plane/TwoSidedPlane_BaseColor.png", read_bytes(dir + "TwoSidedPlane_BaseColor.png")}});
  json done = finished(c, submit(c, zip, "application/zip", "?method=box&texture_size=128"));
  EXPECT_EQ(done["state"], "succeeded") << done.dump();
  httplib::MultipartFormDataItems items = {{"file", zip, "plane.zip", "application/zip"},
                                           {"params", R"({"method":"box"})", "", "application/json"}};
  done = finished(c, c.Post("/v1/jobs", items));
  EXPECT_EQ(done["state"], "succeeded") << done.dump();
}

TEST_F(FolderUpload, RefusalsAreProblems) {
  auto c = server_->client();
  const std::string dir = shared_data("gltf/Triangle/");
  const std::string gltf = read_bytes(dir + "Triangle.gltf"), bin = read_bytes(dir + "simpleTriangle.bin");
  // The .gltf alone: the file it names was not sent.
  expect_problem(submit(c, gltf, "model/gltf+json"), 400, "external URI");
  // A files part whose name climbs out of the folder.
  httplib::MultipartFormDataItems climb = {{"file", gltf, "Triangle.gltf", "model/gltf+json"},
                                           {"files", bin, "../simpleTriangle.bin", "application/octet-stream"}};
  expect_problem(c.Post("/v1/jobs", climb), 400, "plain relative path");
  // Files sent but not the one named: the worker's inspection refuses it.
  httplib::MultipartFormDataItems missing = {{"file", gltf, "Triangle.gltf", "model/gltf+json"},
                                             {"files", bin, "other.bin", "application/octet-stream"}};
  expect_problem(c.Post("/v1/jobs", missing), 400, "not found");
  // Zip entries: climbing out, no model, a bomb (64 MiB of zeros, ~64 KiB packed).
  expect_problem(submit(c, make_zip({{"../Triangle.gltf", gltf}}), "application/zip"), 400, "plain relative path");
  expect_problem(submit(c, make_zip({{"simpleTriangle.bin", bin}}), "application/zip"), 400, "no .gltf");
  expect_problem(submit(c, make_zip({{"Triangle.gltf", gltf}, {"zeros.bin", std::string(64 << 20, '\0')}}),
                        "application/zip"),
                 413, "zip bomb");
  expect_problem(submit(c, "PK not really a zip", "application/zip"), 400, "not a readable zip");
}

}  // namespace
