// A one-line progress bar on standard error for long work (DESIGN §8): "label [###   ] 3/10",
// redrawn in place on a terminal; into a file or pipe, one line "label: 3/10" per tenth.
// step() may be called from several threads. Drawn only when `show` is set and progress is
// enabled (the CLI's -q turns it off for every command).
#pragma once

#include <atomic>
#include <cstddef>
#include <mutex>
#include <string>

namespace bimart {

// When the environment variable BIMART_PROGRESS_FILE names a file (bimart sweep sets it
// for each job it runs), progress is also written there as JSON {"label", "done",
// "total"}, replaced atomically at most once a second and at the end. Every ProgressBar
// reports; loops without a bar (training) call this.
void report_progress(const std::string& label, std::size_t done, std::size_t total);

void set_progress_enabled(bool enabled);
bool progress_enabled();

class ProgressBar {
 public:
  ProgressBar(std::string label, std::size_t total, bool show);
  ~ProgressBar();  // ends the line
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void step();

 private:
  void draw();
  std::string label_;
  std::size_t total_;
  bool show_;
  bool tty_;
  int last_tenth_ = -1;
  std::atomic<std::size_t> done_{0};
  std::mutex mutex_;
};

}  // namespace bimart
