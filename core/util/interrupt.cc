#include "core/util/interrupt.h"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>

namespace bimart {
namespace {

// Fixed storage, so the handler only reads plain memory and calls unlink and _exit
// (async-signal-safe). Writes beyond the slots still work, without the clean-up.
constexpr int kSlots = 64;
constexpr std::size_t kPathMax = 4096;
char paths[kSlots][kPathMax];
std::atomic<bool> claimed[kSlots];  // a writer owns the slot
std::atomic<bool> active[kSlots];   // its path is complete: the handler removes it

void on_signal(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (active[i].load()) ::unlink(paths[i]);
  const char msg[] = "\ninterrupted\n";
  ssize_t ignored = ::write(STDERR_FILENO, msg, sizeof msg - 1);
  (void)ignored;
  ::_exit(128 + sig);
}

}  // namespace

void install_interrupt_handlers() {
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

InterruptCleanup::InterruptCleanup(const std::string& path) : slot_(-1) {
  if (path.size() >= kPathMax) return;
  for (int i = 0; i < kSlots; ++i) {
    if (claimed[i].exchange(true)) continue;
    std::memcpy(paths[i], path.c_str(), path.size() + 1);
    active[i] = true;
    slot_ = i;
    return;
  }
}

InterruptCleanup::~InterruptCleanup() {
  if (slot_ < 0) return;
  active[slot_] = false;
  claimed[slot_] = false;
}

namespace {
volatile std::sig_atomic_t stop_flag = 0;
// A name of its own: extern "C" names are global across the program and its libraries.
extern "C" void bimart_stop_signal_scope_handler(int) { stop_flag = 1; }
}  // namespace

StopSignalScope::StopSignalScope() {
  struct sigaction sa{};
  sa.sa_handler = bimart_stop_signal_scope_handler;
  sigemptyset(&sa.sa_mask);
  stop_flag = 0;
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
}

StopSignalScope::~StopSignalScope() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

bool StopSignalScope::stop_requested() const { return stop_flag != 0; }

}  // namespace bimart
