// One sweep job, run to its end by `bimart sweep job DIR KEY` (docs/sweeps.md): the same
// program runs it whatever started it — the local backend's child, or a Slurm batch
// script. It checks that the job is not done and its dependencies are, writes the job's
// config, runs the job's bimart command with its output on this process's stdout (the
// job's log.txt), forwards SIGTERM/SIGINT (the command checkpoints and stops), and marks
// the job done (done.json) when its result is there.
//
// A training with nodes × tasks_per_node > 1 processes runs data-parallel
// (core/diffusion/distributed.h): inside a Slurm allocation as one `srun` step of that
// many tasks (the tasks find their rank and the master from Slurm's variables); elsewhere
// as that many processes on this machine on loopback.
#pragma once

#include <string>
#include <vector>

#include "core/sweep/plan.h"

namespace bimart::sweep {

struct JobRunOptions {
  std::string program;  // the bimart executable ("" = this program)
  int threads = 1;      // compute threads of each process
};

// 0: done (or was done before); 130: interrupted (a rerun continues it); 1: failed.
// Throws bimart::Error for an unknown key or a dependency that is not done.
int run_job(const Plan& plan, const std::string& key, const JobRunOptions& options);

// The job's bimart command: program --threads T ARGS [--resume].
std::vector<std::string> job_command(const Job& job, const std::string& program, int threads);
// True when the job is a training with a checkpoint to continue from.
bool resumes_checkpoint(const Job& job);
// How many processes the job runs as (nodes × tasks_per_node for a training, else 1).
int job_processes(const Job& job);
// This executable's path (/proc/self/exe).
std::string self_program();

}  // namespace bimart::sweep
