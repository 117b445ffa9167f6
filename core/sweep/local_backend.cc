#include "core/sweep/local_backend.h"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <thread>

#include <fmt/format.h>

#include "core/sweep/job_runner.h"
#include "core/sweep/job_state.h"
#include "core/util/error.h"
#include "core/util/interrupt.h"
#include "core/util/subprocess.h"
#include "core/util/text.h"

namespace bimart::sweep {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

enum class State { Pending, Running, Done, Failed, Skipped };

struct Running {
  pid_t pid = -1;
  int threads = 1;
  Clock::time_point started, last_report;
  ProgressWatch progress;
};

// `program --threads T sweep job DIR KEY` (core/sweep/job_runner.h) with its output in the
// job's log; the runner runs the job's command, forwards SIGTERM and marks the job done.
pid_t launch(const Plan& plan, const Job& job, const std::string& program, int threads) {
  fs::create_directories(job.folder);
  const std::string log = log_file(job);
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) throw Error("cannot write " + log + ": " + std::strerror(errno));
  const std::vector<std::string> argv{program, "--threads", std::to_string(threads), "sweep", "job", plan.dir, job.key};
  try {
    const pid_t pid = start_child(argv, {}, fd);
    ::close(fd);
    return pid;
  } catch (...) {
    ::close(fd);
    throw;
  }
}

}  // namespace

RunSummary run_local(const Plan& plan, const LocalOptions& o) {
  const auto t0 = Clock::now();
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int jobs = std::max(1, o.jobs);
  const int total_threads = o.threads > 0 ? o.threads : cores;
  const int per_job = std::max(1, total_threads / jobs);  // when `jobs` run side by side
  const std::string program = o.program.empty() ? self_program() : o.program;
  const auto rates = read_rates(plan.dir);

  RunSummary sum;
  std::vector<State> state(plan.jobs.size(), State::Pending);
  const std::vector<bool> needed = needed_jobs(plan);
  for (std::size_t i = 0; i < plan.jobs.size(); ++i)
    if (!needed[i]) {  // done, or only feeding results that are done
      state[i] = State::Done;
      ++sum.already_done;
    }
  const int to_run = static_cast<int>(plan.jobs.size()) - sum.already_done;
  if (!o.quiet)
    std::cout << fmt::format("sweep {}: {} jobs, {} done before, {} to run ({} at a time, {} thread{} each; a job "
                             "that starts alone gets {})\n",
                             plan.name, plan.jobs.size(), sum.already_done, to_run, jobs, per_job, per_job == 1 ? "" : "s",
                             total_threads)
              << std::flush;

  const StopSignalScope signals;  // Ctrl-C, SIGTERM: stop the children first

  std::map<std::size_t, Running> running;
  int started = 0;
  bool stopping = false;
  while (true) {
    if (signals.stop_requested() && !stopping) {
      stopping = true;
      sum.interrupted = true;
      if (!running.empty())
        std::cout << fmt::format("stopping: {} running job{} write their checkpoints and stop\n", running.size(),
                                 running.size() == 1 ? "" : "s")
                  << std::flush;
      for (const auto& [i, r] : running) ::kill(r.pid, SIGTERM);
    }
    // Start what is ready. The threads not used by running jobs are divided among the jobs
    // starting now, so a job that can only run alone (the last generation of a sweep) gets
    // them all; a later job that finds them taken gets one (it oversubscribes a little).
    std::vector<std::size_t> ready;
    for (std::size_t i = 0; i < plan.jobs.size() && !stopping; ++i) {
      if (state[i] != State::Pending) continue;
      bool all_done = true, blocked = false;
      for (const std::size_t d : plan.jobs[i].deps) {
        all_done = all_done && state[d] == State::Done;
        blocked = blocked || state[d] == State::Failed || state[d] == State::Skipped;
      }
      if (blocked) {
        state[i] = State::Skipped;
        ++sum.skipped;
      } else if (all_done) {
        ready.push_back(i);
      }
    }
    int free_threads = total_threads;
    for (const auto& [i, r] : running) free_threads -= r.threads;
    int slots = std::min(static_cast<int>(ready.size()), jobs - static_cast<int>(running.size()));
    for (std::size_t n = 0; slots > 0; ++n, --slots) {
      const std::size_t i = ready[n];
      const Job& job = plan.jobs[i];
      const bool resumes = resumes_checkpoint(job);
      Running r;
      r.threads = std::max(1, free_threads / slots);
      free_threads -= r.threads;
      r.pid = launch(plan, job, program, r.threads);
      r.started = r.last_report = Clock::now();
      running[i] = r;
      state[i] = State::Running;
      ++started;
      if (!o.quiet)
        std::cout << fmt::format("[{}/{}] start {}: {} thread{}, estimate {}{}, log {}\n", started, to_run, job_label(job),
                                 r.threads, r.threads == 1 ? "" : "s", format_duration(estimate_seconds(job, rates, r.threads)),
                                 resumes ? " (resumes its checkpoint)" : "", log_file(job))
                  << std::flush;
    }
    if (running.empty()) {
      bool any_ready = false;
      for (std::size_t i = 0; i < plan.jobs.size(); ++i) any_ready = any_ready || state[i] == State::Pending;
      if (!any_ready || stopping) break;
      continue;  // the loop above marks jobs behind a failure as skipped
    }
    // Reap finished children.
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid > 0) {
      for (auto it = running.begin(); it != running.end(); ++it) {
        if (it->second.pid != pid) continue;
        const Job& job = plan.jobs[it->first];
        const double secs = std::chrono::duration<double>(Clock::now() - it->second.started).count();
        // The runner marks the job done (and records its rate) when its result is there.
        const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && is_done(job);
        if (ok) {
          state[it->first] = State::Done;
          ++sum.ran;
          if (!o.quiet)
            std::cout << fmt::format("done  {} in {}\n", job_label(job), format_duration(secs)) << std::flush;
        } else if (stopping) {
          state[it->first] = State::Pending;  // interrupted: a rerun continues it
          if (!o.quiet) std::cout << fmt::format("stopped {} (a rerun continues it)\n", job_label(job)) << std::flush;
        } else {
          state[it->first] = State::Failed;
          ++sum.failed;
          std::cout << fmt::format("FAILED {} ({}); the end of {}:\n{}", job_label(job), exit_status_text(status), log_file(job),
                                   log_tail(job, 12))
                    << std::flush;
        }
        running.erase(it);
        break;
      }
      continue;
    }
    // Progress of the running jobs.
    const auto now = Clock::now();
    for (auto& [i, r] : running) {
      const Progress p = r.progress.look(plan.jobs[i]);
      if (o.quiet || std::chrono::duration<double>(now - r.last_report).count() < o.report_every) continue;
      r.last_report = now;
      std::string line = fmt::format("      {}: running {}", job_label(plan.jobs[i]),
                                     format_duration(std::chrono::duration<double>(now - r.started).count()));
      if (p.known) {
        const double rate = r.progress.rate();
        line += fmt::format(", {} {:.0f}/{:.0f}", p.label, p.done, p.total);
        if (rate > 0)
          line += fmt::format(", {:.2f}/s, {} left", rate, format_duration((p.total - p.done) / rate));
      }
      std::cout << line << "\n" << std::flush;
    }
    ::usleep(200 * 1000);  // a signal ends it at once (EINTR), so SIGTERM reaches the children without delay
  }
  sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return sum;
}

}  // namespace bimart::sweep
