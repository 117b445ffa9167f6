// Runs the `bimart` binary (BIMART_CLI, set by the test's CMakeLists.txt) with arguments,
// for tests that drive whole commands.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace bimart::test {

struct CliRun {
  int status;          // pclose()'s status: 0 on success
  std::string output;  // stdout and stderr
};

// Runs a shell command line and collects its stdout and stderr.
inline CliRun run_shell(const std::string& command) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  return {pclose(p), out};
}

inline CliRun run_bimart(const std::string& args) { return run_shell(std::string(BIMART_CLI) + " " + args); }

// The exit code of a finished run; -1 when it did not exit normally (a signal).
inline int exit_code(const CliRun& r) { return WIFEXITED(r.status) ? WEXITSTATUS(r.status) : -1; }

}  // namespace bimart::test
