// Runs a sweep's jobs on this machine (docs/sweeps.md): each job is `bimart sweep job DIR
// KEY` (core/sweep/job_runner.h), started as a child process with its output in the job's
// log.txt, up to `jobs` at once with the threads divided between them. Finished jobs
// (done.json with their key) are skipped; an unfinished training continues from its
// checkpoint (train --resume) and an unfinished generation keeps the windows it wrote
// (generate --resume). Children are stopped with SIGTERM (and checkpoint) when the sweep
// is interrupted or killed.
#pragma once

#include <string>

#include "core/sweep/plan.h"

namespace bimart::sweep {

struct LocalOptions {
  int jobs = 1;               // jobs side by side
  int threads = 0;            // compute threads in all (0 = all cores); each job gets threads / jobs
  std::string program;        // the bimart executable ("" = this program)
  double report_every = 30;   // seconds between progress lines of a running job
  bool quiet = false;         // no progress lines
};

struct RunSummary {
  int already_done = 0, ran = 0, failed = 0, skipped = 0;  // skipped: a dependency failed
  int pending = 0;  // still queued or running elsewhere when the backend returned (Slurm)
  bool interrupted = false;
  double seconds = 0;
};

RunSummary run_local(const Plan& plan, const LocalOptions& options);

}  // namespace bimart::sweep
