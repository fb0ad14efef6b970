// SPDX-License-Identifier: Apache-2.0
#pragma once
// Helpers for tests that run real processes: unique segment names and a forked child whose exit status is checked.

#include <sys/wait.h>
#include <unistd.h>

#include <string>

namespace impetus::test {

// A segment name no other test (or concurrent ctest process) uses.
inline std::string unique_segment_name(const std::string& what) {
  static int counter = 0;
  return "impetus_test_" + std::to_string(getpid()) + "_" + std::to_string(counter++) + "_" + what;
}

// Runs body() in a child process, which exits with body's return value without running the parent's destructors
// (the child shares the test framework's state, which must not be torn down twice). Returns the child's pid.
template <class Body>
pid_t fork_child(Body&& body) {
  const pid_t pid = fork();
  if (pid == 0) _exit(body());
  return pid;
}

// Exit status of a child, or -1 if it did not exit normally.
inline int wait_child(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace impetus::test
