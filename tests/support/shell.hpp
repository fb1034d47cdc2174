// Running a command line from a test: its exit status and output (stdout and stderr).
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

#include "tests/support/test_support.hpp"

namespace kanegen::test {

struct ShellRun {
  int status;       ///< exit status; -1 if the command did not exit (a signal)
  std::string out;  ///< stdout and stderr
};

inline ShellRun shell(const std::string& cmd) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  std::string out;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

/// `kanegen ARGS` run in `dir` (a shell-safe path).
inline ShellRun run_kanegen(const std::string& args, const std::string& dir = ".") {
  return shell("cd '" + dir + "' && " + std::string(kanegen_binary()) + " " + args);
}

}  // namespace kanegen::test
