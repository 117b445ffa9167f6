// Ctrl-C and kill: the program ends with exit code 130 (SIGINT) or 143 (SIGTERM) and
// leaves no partial output: the temporary files of writes in progress
// (core/util/atomic_file.h) are removed first. Targets of writes are never touched.
#pragma once

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

}  // namespace bimart
