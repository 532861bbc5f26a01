// OpenMP threads that wait for work should sleep, not spin.
//
// libgomp's waiting threads spin by default. The pipeline runs two
// branches' thread teams side by side (field and proxy, run_map.cpp) on a
// machine with few cores, where a spinning waiter of one team takes the
// core from the other team's workers: on 2 cores, robot-arm's map took
// 9.3 s spinning and 5.4 s sleeping (docs/tuning.md, "OpenMP's waiting").
// libgomp reads OMP_WAIT_POLICY once, when it loads, before main(): a
// program that wants the policy sets it and executes itself again.
#pragma once

namespace soupuv {

// The value the programs and the server's workers give OMP_WAIT_POLICY.
inline constexpr const char* kOpenMpWaitPolicy = "passive";

// When OMP_WAIT_POLICY is unset: sets it to kOpenMpWaitPolicy and executes
// the running program (/proc/self/exe) again with argv; does not return
// then. A caller's own setting is kept; if the exec fails the program runs
// on with libgomp's default.
void exec_with_sleeping_openmp_waiters(char** argv);

}  // namespace soupuv
