#pragma once
// Test helper: runs a shell command line and returns its exit code and its output (stdout and
// stderr together), for the tests that run the repository's Python scripts.
#include <cstdio>
#include <string>

#include <sys/wait.h>

namespace robustness {

struct ShellResult {
  int exit_code = -1;  // -1 when it did not exit normally
  std::string out;     // stdout and stderr
};

inline ShellResult shell(const std::string& cmd) {
  ShellResult r;
  FILE* p = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[512];
  while (std::fgets(buf, sizeof(buf), p)) r.out += buf;
  const int status = ::pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace robustness
