// Ctrl-C and kill: the program ends with exit code 130 (SIGINT) or 143 (SIGTERM) and
// leaves no partial output: the temporary files of writes in progress
// (core/util/atomic_file.h) are removed first. Targets of writes are never touched.
#pragma once

#include <signal.h>

#include <string>

namespace bimart {

// Installs the handlers (the CLI does, once, at start-up).
void install_interrupt_handlers();

// A temporary file that the handler removes if the program is interrupted while it exists.
class InterruptCleanup {
 public:
  explicit InterruptCleanup(const std::string& path);
  ~InterruptCleanup();
  InterruptCleanup(const InterruptCleanup&) = delete;
  InterruptCleanup& operator=(const InterruptCleanup&) = delete;

 private:
  int slot_;
};

// While alive, SIGINT and SIGTERM only set a flag instead of ending the program, so a
// loop that runs children can stop them first (bimart sweep's backends and job runner);
// the previous handlers come back at the end of the scope. One scope at a time.
class StopSignalScope {
 public:
  StopSignalScope();
  ~StopSignalScope();
  StopSignalScope(const StopSignalScope&) = delete;
  StopSignalScope& operator=(const StopSignalScope&) = delete;
  // True once SIGINT or SIGTERM arrived in this scope.
  bool stop_requested() const;

 private:
  struct sigaction old_int_{}, old_term_{};
};

}  // namespace bimart
