// What a sweep job has left on disk, read the same way by every backend and by `bimart
// sweep status`: done.json (written last, atomically, with the job's key) marks a finished
// job; progress.json is the running command's progress (BIMART_PROGRESS_FILE); log.txt its
// output. A folder whose done.json holds another key is not done.
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/sweep/plan.h"

namespace bimart::sweep {

std::string done_file(const Job& job);
std::string log_file(const Job& job);
std::string progress_file(const Job& job);

// True when done.json exists, holds this job's key, and the job's result file exists.
bool is_done(const Job& job);
// Which jobs still have to run: those not done that a result needs. A finished
// evaluation needs neither its samples nor its models any more, so a sweep folder whose
// bulky outputs were deleted (or never copied) reruns nothing that is not missing.
// `done_elsewhere`: indices of jobs counted as done too (those --reuse would take).
std::vector<bool> needed_jobs(const Plan& plan, const std::vector<std::size_t>& done_elsewhere = {});

// Jobs finished in another sweep's folder (`--reuse DIR`): train and eval jobs of `plan` not
// done in its own folder whose folder under one of `sweeps` (the same relative path, so the
// same key) is done. Returns (job index, that folder), the first sweep that has it.
std::vector<std::pair<std::size_t, std::string>> finished_elsewhere(const Plan& plan,
                                                                    const std::vector<std::string>& sweeps);
// Copies those jobs' files into this sweep's folders (everything but the training state,
// checkpoint.npz, which a finished training no longer needs), done.json last.
void adopt_finished(const Plan& plan, const std::vector<std::pair<std::size_t, std::string>>& found);

// A JSON file's content ({} when absent or unreadable).
nlohmann::json read_json_or_empty(const std::string& path);
// done.json's content ({} when absent or unreadable).
nlohmann::json read_done(const Job& job);
// Writes done.json: the key, seconds, threads, work and rate (work units per second).
void mark_done(const Job& job, double seconds, int threads);

struct Progress {
  std::string label;
  double done = 0, total = 0;
  bool known = false;
};
Progress read_progress(const Job& job);

// Follows a running job's progress: the current phase (its label) from its first reading
// to its last, and when each was seen (a resumed training: this run's steps only).
class ProgressWatch {
 public:
  Progress look(const Job& job);  // reads progress.json now; a new label starts a new phase
  // The phase's units per second from its first reading to its last; 0 until it has
  // advanced over more than a second.
  double rate() const;
  // The job's work units per second of one thread of one process (for record_rate).
  double work_per_thread(const Job& job, int threads, int processes) const;

 private:
  std::string label_;
  double first_done_ = -1, last_done_ = -1, total_ = 0;
  std::chrono::steady_clock::time_point first_seen_, last_seen_;
};

// How much faster one job runs with `threads` threads than with one.
double thread_speedup(int threads);
// "2026-12-05T09:20:34Z".
std::string utc_now_text();

// The last `lines` lines of the job's log ("" when there is none).
std::string log_tail(const Job& job, int lines);

// Measured rates (work units per second and thread) by rate key, kept in DIR/rates.json.
std::map<std::string, double> read_rates(const std::string& dir);
void record_rate(const std::string& dir, const std::string& rate_key, double per_thread);
// Seconds a job should take with `threads` threads: from a measured rate when there is
// one, else from defaults measured on the 2-core machine (docs/performance.md).
double estimate_seconds(const Job& job, const std::map<std::string, double>& rates, int threads);

// plan.json: the jobs (kind, name, key, folder, command, dependencies) and rows, for
// `bimart sweep status` and cluster backends.
void write_plan_json(const Plan& plan);
Plan read_plan_json(const std::string& dir);

}  // namespace bimart::sweep
