// The jobs of a sweep (docs/sweeps.md): train each model that is not a ready file,
// generate each distinct run of the evaluation windows, evaluate each (run, output) pair.
// Every job is keyed by a fingerprint of everything that decides its result — the training
// config after overrides, the data, the checkpoints it reads, the pipeline text and
// overrides, the evaluation set — and lives in a folder named by that key, so a finished
// job is never redone, identical rows share their jobs, and a changed row redoes only what
// its change reaches.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/sweep/sweep_file.h"

namespace bimart::sweep {

enum class JobKind { Train, Generate, Eval };
const char* job_kind_name(JobKind kind);  // "train", "generate", "eval"

struct Job {
  JobKind kind = JobKind::Train;
  std::string name;    // what it makes: a model name, or the rows it serves ("w C, NP-BPS")
  std::string key;     // 16 hex digits
  std::string folder;  // its outputs, log.txt, progress.json and, when finished, done.json
  std::vector<std::string> args;  // the bimart command (without the program and --threads)
  std::vector<std::size_t> deps;  // jobs that must be done first (indices into Plan::jobs)
  std::string config_text;        // train: the config written to folder/config.yaml
  std::string result;             // the file a finished job leaves (model, metrics JSON)
  // For estimates and progress: `work` units of `unit` ("windows": training windows =
  // steps × batch; "window-samples": evaluation windows × samples; "sequences").
  double work = 0;
  std::string unit;
  std::string rate_key;  // measured rates are stored and looked up under this key
  // Cluster backends: how many processes a training may use.
  int nodes = 1, tasks_per_node = 1, cpus_per_task = 0;
};

// "train motion", "generate w C, NP-BPS": how progress lines and logs name a job.
std::string job_label(const Job& job);

struct RowPlan {
  std::string name, section, output;
  std::size_t generate = 0, eval = 0;  // job indices
  std::map<std::string, double> paper;
};

struct Plan {
  std::string sweep_file;
  std::string name;
  std::string dir;
  std::vector<Job> jobs;  // dependencies first
  std::vector<RowPlan> rows;
};

// Plans the jobs of `file` with outputs under `dir`. Checks, before anything runs, every
// training config (after overrides) and every row's pipeline (after its overrides) and
// reports mistakes with the sweep file's line. `windows` is the number of evaluation
// windows (for estimates; 0 = read from the data set).
Plan make_plan(const SweepFile& file, const std::string& dir);

}  // namespace bimart::sweep
