#include "core/util/progress.h"

#include <fmt/format.h>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <mutex>

#include "core/util/atomic_file.h"
#include "core/util/error.h"

namespace bimart {

namespace {
std::atomic<bool> enabled{true};
}  // namespace

void report_progress(const std::string& label, std::size_t done, std::size_t total) {
  static const char* const file = std::getenv("BIMART_PROGRESS_FILE");
  if (file == nullptr || *file == '\0') return;
  static std::mutex mutex;
  static auto last = std::chrono::steady_clock::time_point{};
  std::lock_guard<std::mutex> lock(mutex);
  const auto now = std::chrono::steady_clock::now();
  if (done < total && now - last < std::chrono::seconds(1)) return;
  last = now;
  try {
    write_file_atomically(file, [&](std::ostream& o) {
      o << fmt::format("{{\"label\": \"{}\", \"done\": {}, \"total\": {}}}\n", label, done, total);
    });
  } catch (const Error&) {
    // Progress is a courtesy: a failed write must not stop the work.
  }
}

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
  const std::size_t done = done_;
  report_progress(label_, done, total_);
  if (!show_) return;
  std::lock_guard<std::mutex> lock(mutex_);
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
