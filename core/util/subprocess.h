// Running another program and reading what it printed: the cluster backend's sbatch,
// squeue and scancel calls (core/sweep/slurm_backend.cc). Written on fork/execvp because
// no Debian C++ library in our set covers it; Boost.Process would be the one dependency
// for a few dozen lines.
#pragma once

#include <string>
#include <vector>

namespace bimart {

struct CommandResult {
  int exit_code = -1;  // the program's exit code; 128 + N when killed by signal N; 127: not found
  std::string out, err;
};

// Runs argv[0] (looked up on PATH) with argv, waits for it, returns its output.
// Throws bimart::Error only when the process cannot be started at all.
CommandResult run_command(const std::vector<std::string>& argv);

// The full path of `name` on PATH, or "" when there is none.
std::string find_program(const std::string& name);

}  // namespace bimart
