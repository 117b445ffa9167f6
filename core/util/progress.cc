#include "core/util/progress.h"

#include <fmt/format.h>

#include <unistd.h>

#include <iostream>

namespace bimart {

namespace {
std::atomic<bool> enabled{true};
}  // namespace

void set_progress_enabled(bool e) { enabled = e; }
bool progress_enabled() { return enabled; }

ProgressBar::ProgressBar(std::string label, std::size_t total, bool show)
    : label_(std::move(label)), total_(total), show_(show && enabled), tty_(isatty(STDERR_FILENO) != 0) {
  draw();
}

ProgressBar::~ProgressBar() {
  if (show_ && tty_) std::cerr << "\n";
}

void ProgressBar::step() {
  ++done_;
  draw();
}

void ProgressBar::draw() {
  if (!show_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const std::size_t done = done_;
  constexpr int kWidth = 30;
  const int filled = total_ ? static_cast<int>(kWidth * done / total_) : kWidth;
  if (!tty_) {  // a log file: one line per tenth, not a redrawn bar
    const int tenth = total_ ? static_cast<int>(10 * done / total_) : 10;
    if (tenth == last_tenth_) return;
    last_tenth_ = tenth;
    std::cerr << fmt::format("{}: {}/{}\n", label_, done, total_) << std::flush;
    return;
  }
  std::cerr << fmt::format("\r{} [{}{}] {}/{}", label_, std::string(filled, '#'), std::string(kWidth - filled, ' '),
                           done, total_)
            << std::flush;
}

}  // namespace bimart
