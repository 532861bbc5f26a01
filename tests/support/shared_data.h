// The shared sample data (../shared/data) that a clone of the repository alone
// does not have. A test that needs it calls shared_data_dir(): when the folder
// is absent the test process prints why and exits with code 77, which ctest
// counts as skipped (SKIP_RETURN_CODE 77 on every gtest suite; ctest runs each
// test in its own process), so only the tests that need the data are skipped.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace soupuv_test {

inline constexpr int kSkipExitCode = 77;

inline std::string shared_data_dir() {
  const std::string dir = SOUPUV_SHARED_DATA;
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    std::printf("SKIPPED: needs the shared sample data, absent at %s (clone ../shared next to the repository)\n",
                dir.c_str());
    std::fflush(stdout);
    std::_Exit(kSkipExitCode);
  }
  return dir;
}

}  // namespace soupuv_test
