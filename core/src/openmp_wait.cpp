#include "soupuv/openmp_wait.h"

#include <unistd.h>

#include <cstdlib>

namespace soupuv {

void exec_with_sleeping_openmp_waiters(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;
  if (setenv("OMP_WAIT_POLICY", kOpenMpWaitPolicy, 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Not executed again (no /proc, say): run on as loaded, and do not tell a
  // child process the policy this one does not have.
  unsetenv("OMP_WAIT_POLICY");
}

}  // namespace soupuv
