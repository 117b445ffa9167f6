#include "core/util/progress.h"

#include <fmt/format.h>

#include <iostream>

namespace bimart {

ProgressBar::ProgressBar(std::string label, std::size_t total, bool show)
    : label_(std::move(label)), total_(total), show_(show) {
  draw();
}

ProgressBar::~ProgressBar() {
  if (show_) std::cerr << "\n";
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
  std::cerr << fmt::format("\r{} [{}{}] {}/{}", label_, std::string(filled, '#'), std::string(kWidth - filled, ' '),
                           done, total_)
            << std::flush;
}

}  // namespace bimart
