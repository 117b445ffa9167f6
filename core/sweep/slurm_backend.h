// Runs a sweep's jobs on a Slurm cluster (docs/cluster.md): every job that is still needed
// becomes one batch job, `bimart sweep job DIR KEY` (core/sweep/job_runner.h), submitted
// with sbatch and chained to the jobs it needs (--dependency=afterok), so the whole sweep
// is in Slurm's queue at once and runs while nobody watches. A training of nodes ×
// tasks_per_node processes gets that allocation and runs as one srun step. The sweep
// folder must be on a file system the nodes share, at the same path.
//
// A job already in the queue (its id is in the job's slurm.json and squeue still lists it
// as pending or running) is not submitted again, so rerunning the sweep is always safe; a
// job that ended unfinished (scancel, time limit, node failure) is submitted again and
// continues from its checkpoint. Jobs are submitted with --requeue: when Slurm requeues a
// preempted job, it resumes the same way.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/sweep/local_backend.h"
#include "core/sweep/plan.h"

namespace bimart::sweep {

struct SlurmOptions {
  std::string partition, account, time_limit;  // sbatch --partition, --account, --time ("" = the cluster's default)
  std::vector<std::string> sbatch_args;        // more sbatch options, as given
  std::string program;                         // bimart on the nodes ("" = this program's path)
  int cpus_per_task = 0;       // for jobs whose model does not set cpus_per_task (0 = Slurm's default, one thread)
  bool wait = true;            // false: submit and return (--detach)
  double report_every = 30;    // seconds between progress lines of a running job
  double poll_seconds = 5;     // seconds between squeue calls while waiting
  bool quiet = false;
};

// Submits what is needed and, with `wait`, follows the jobs until they end. In the summary
// `ran` counts jobs finished while waiting, `pending` the jobs left in Slurm's queue.
RunSummary run_slurm(const Plan& plan, const SlurmOptions& options);

struct SlurmJobState {
  std::string state;   // PENDING, RUNNING, COMPLETED, FAILED, CANCELLED, TIMEOUT, ...
  std::string reason;  // why it is pending (Dependency, Resources, ...)
  std::string nodes;   // where it runs
};
// "PENDING (Dependency)", "RUNNING on n12", "CANCELLED".
std::string slurm_state_text(const SlurmJobState& state);
// The jobs squeue lists for this user (finished ones only for a few minutes), by id.
std::map<long, SlurmJobState> slurm_jobs();
// The id of the Slurm job last submitted for `job` (its slurm.json), 0 when none.
long submitted_id(const Job& job);
// True for states in which a job will still run (pending, running, requeued, ...).
bool slurm_state_live(const std::string& state);
// True when sbatch is on PATH.
bool slurm_available();

}  // namespace bimart::sweep
