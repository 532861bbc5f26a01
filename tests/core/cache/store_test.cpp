#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "soupuv/cache/bytes.h"
#include "soupuv/cache/store.h"

using namespace soupuv::cache;
namespace fs = std::filesystem;

namespace {
fs::path fresh_dir(const std::string& name) {
  fs::path d = fs::path(SOUPUV_BINARY_DIR) / "test-tmp" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
Bytes bytes_of(size_t n, uint8_t seed) {
  Bytes b(n);
  for (size_t i = 0; i < n; ++i) b[i] = uint8_t(seed + i * 7);
  return b;
}
}  // namespace

TEST(CacheKey, DependsOnEveryPartAndItsBoundaries) {
  EXPECT_EQ(cache_key({"a", "b"}), cache_key({"a", "b"}));
  EXPECT_NE(cache_key({"a", "b"}), cache_key({"a", "c"}));
  EXPECT_NE(cache_key({"ab", ""}), cache_key({"a", "b"}));
  EXPECT_EQ(cache_key({"x"}).size(), 32u);
}

TEST(Store, LruEvictsOldestBeyondBudget) {
  Store s({.memory_bytes = 300, .directory = ""});
  s.put("k1", bytes_of(100, 1));
  s.put("k2", bytes_of(100, 2));
  s.put("k3", bytes_of(100, 3));
  ASSERT_TRUE(s.get("k1"));  // k1 now most recent
  s.put("k4", bytes_of(100, 4));  // evicts k2
  EXPECT_FALSE(s.get("k2"));
  EXPECT_TRUE(s.get("k1"));
  EXPECT_TRUE(s.get("k3"));
  EXPECT_EQ(*s.get("k4"), bytes_of(100, 4));
  auto st = s.stats();
  EXPECT_EQ(st.evictions, 1u);
  EXPECT_LE(st.memory_bytes, 300u);
  EXPECT_EQ(st.misses, 1u);
}

TEST(Store, DirectorySurvivesANewStoreAndRejectsCorruptFiles) {
  fs::path dir = fresh_dir("store_disk");
  {
    Store s({.memory_bytes = 1 << 20, .directory = dir.string()});
    s.put("0123abcd", bytes_of(5000, 9));
  }
  Store t({.memory_bytes = 1 << 20, .directory = dir.string()});
  auto v = t.get("0123abcd");
  ASSERT_TRUE(v);
  EXPECT_EQ(*v, bytes_of(5000, 9));
  EXPECT_EQ(t.stats().disk_hits, 1u);
  EXPECT_TRUE(t.get("0123abcd"));
  EXPECT_EQ(t.stats().memory_hits, 1u);

  // Flip one payload byte on disk: a new store must not trust it.
  fs::path file = dir / "01" / "0123abcd.bin";
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-10, std::ios::end);
    f.put('\x55');
  }
  Store u({.memory_bytes = 1 << 20, .directory = dir.string()});
  EXPECT_FALSE(u.get("0123abcd"));
  EXPECT_EQ(u.stats().corrupt_files, 1u);
  // No temporary files are left behind.
  for (auto& e : fs::recursive_directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
}

TEST(Store, SeveralProcessesWritingTheSameKeyLeaveOneValidFile) {
  fs::path dir = fresh_dir("store_procs");
  std::vector<pid_t> kids;
  for (int i = 0; i < 4; ++i) {
    pid_t pid = fork();
    if (pid == 0) {
      Store s({.memory_bytes = 0, .directory = dir.string()});
      for (int r = 0; r < 20; ++r) s.put("feedbeef", bytes_of(200000, 3));
      _exit(0);
    }
    kids.push_back(pid);
  }
  // Meanwhile read: every read is either a miss or the whole value.
  Store reader({.memory_bytes = 0, .directory = dir.string()});
  for (int r = 0; r < 200; ++r) {
    auto v = reader.get("feedbeef");
    if (v) {
      EXPECT_EQ(*v, bytes_of(200000, 3));
    }
  }
  for (pid_t k : kids) {
    int status = 0;
    waitpid(k, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  EXPECT_EQ(reader.stats().corrupt_files, 0u);
  ASSERT_TRUE(reader.get("feedbeef"));
}

TEST(ByteCodec, RoundTripsAndRejectsTruncation) {
  ByteWriter w;
  w.put<int>(42);
  w.put_vector(std::vector<double>{1.5, -2.5});
  w.put_string("hello");
  Bytes b = w.take();
  ByteReader r(b);
  EXPECT_EQ(r.get<int>(), 42);
  EXPECT_EQ(r.get_vector<double>(), (std::vector<double>{1.5, -2.5}));
  EXPECT_EQ(r.get_string(), "hello");
  EXPECT_TRUE(r.done());
  b.pop_back();
  ByteReader bad(b);
  bad.get<int>();
  bad.get_vector<double>();
  EXPECT_THROW(bad.get_string(), soupuv::Error);
}
