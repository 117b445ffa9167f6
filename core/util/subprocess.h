// Running other programs: reading what a short one printed (the Slurm backend's sbatch
// and squeue calls), and starting a long one as a child that ends with this process (the
// sweep's jobs, core/sweep/). Written on fork/exec because no Debian C++ library in our
// set covers it; Boost.Process would be the one dependency for a few dozen lines.
#pragma once

#include <sys/types.h>

#include <map>
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

// Starts argv[0] (looked up on PATH) with `env` added to the environment and, when
// output_fd >= 0, its stdout and stderr going there. The child has the default SIGINT and
// SIGTERM handling and receives SIGTERM when this process dies, even by SIGKILL (a bimart
// command then checkpoints and stops as on Ctrl-C). Returns its pid; throws bimart::Error
// when it cannot fork. Reap it with waitpid.
pid_t start_child(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env = {},
                  int output_fd = -1);

// A waitpid status in words: "exit code 3", "signal 9".
std::string exit_status_text(int status);

}  // namespace bimart
