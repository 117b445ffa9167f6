#include "core/sweep/slurm_backend.h"

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/sweep/job_runner.h"
#include "core/sweep/job_state.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/interrupt.h"
#include "core/util/subprocess.h"
#include "core/util/text.h"

namespace bimart::sweep {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

std::string slurm_file(const Job& job) { return (fs::path(job.folder) / "slurm.json").string(); }
// "bimart-table3-train-npa_bps_motion": what squeue shows; Slurm allows most characters,
// but spaces and commas in a row name would make the name awkward to use.
std::string slurm_job_name(const Plan& plan, const Job& job) {
  std::string s = "bimart-" + plan.name + "-" + job_kind_name(job.kind) + "-" + job.name;
  for (char& c : s)
    if (c == ' ' || c == ',' || c == '/' || c == '\'' || c == '"') c = '_';
  return s;
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string write_batch_script(const Plan& plan, const Job& job, const std::string& program) {
  const std::string path = (fs::path(job.folder) / "job.sbatch").string();
  write_file_atomically(path, [&](std::ostream& o) {
    o << "#!/bin/bash\n"
      << "# " << job_label(job) << " (" << job.key << ") of sweep " << plan.name << ", written by bimart sweep --backend slurm.\n"
      << "# Runs the job to its end: checks what it needs, resumes a checkpoint, marks it done (docs/cluster.md).\n"
      << "exec " << shell_quote(program) << " --threads \"${SLURM_CPUS_PER_TASK:-1}\" sweep job " << shell_quote(plan.dir)
      << " " << job.key << "\n";
  });
  fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
  return path;
}

long parse_job_id(const std::string& text) {
  // sbatch --parsable prints "ID" or "ID;CLUSTER".
  std::size_t i = 0;
  while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  long id = 0;
  std::size_t digits = 0;
  for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i, ++digits) id = id * 10 + (text[i] - '0');
  return digits > 0 ? id : 0;
}

std::string trimmed(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t b = 0;
  while (b < s.size() && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  return s.substr(b);
}

long submit(const Plan& plan, const Job& job, const SlurmOptions& o, const std::string& program,
            const std::vector<long>& after) {
  fs::create_directories(job.folder);
  const std::string script = write_batch_script(plan, job, program);
  const int cpus = job.cpus_per_task > 0 ? job.cpus_per_task : o.cpus_per_task;
  std::vector<std::string> argv{"sbatch",
                                "--parsable",
                                "--job-name=" + slurm_job_name(plan, job),
                                "--chdir=" + fs::current_path().string(),
                                "--output=" + log_file(job),
                                "--open-mode=append",
                                "--requeue",
                                "--kill-on-invalid-dep=yes",
                                "--nodes=" + std::to_string(std::max(1, job.kind == JobKind::Train ? job.nodes : 1)),
                                "--ntasks-per-node=" +
                                    std::to_string(std::max(1, job.kind == JobKind::Train ? job.tasks_per_node : 1))};
  if (cpus > 0) argv.push_back("--cpus-per-task=" + std::to_string(cpus));
  if (!o.partition.empty()) argv.push_back("--partition=" + o.partition);
  if (!o.account.empty()) argv.push_back("--account=" + o.account);
  if (!o.time_limit.empty()) argv.push_back("--time=" + o.time_limit);
  if (!after.empty()) {
    std::string dep = "--dependency=afterok";
    for (const long id : after) dep += ":" + std::to_string(id);
    argv.push_back(dep);
  }
  argv.insert(argv.end(), o.sbatch_args.begin(), o.sbatch_args.end());
  argv.push_back(script);
  const CommandResult r = run_command(argv);
  const long id = r.exit_code == 0 ? parse_job_id(r.out) : 0;
  if (id <= 0)
    throw Error(fmt::format("sbatch refused {} ({}): {}\n  the command: {}", job_label(job),
                            r.exit_code == 0 ? "no job id in its answer" : fmt::format("exit code {}", r.exit_code),
                            trimmed(r.err.empty() ? r.out : r.err), join(argv, " ")));
  const json j{{"id", id}, {"key", job.key}, {"submitted", utc_now_text()}, {"sbatch", argv}};
  write_file_atomically(slurm_file(job), [&](std::ostream& out) { out << j.dump(2) << "\n"; });
  return id;
}

}  // namespace

bool slurm_available() { return !find_program("sbatch").empty(); }

bool slurm_state_live(const std::string& s) {
  static const std::set<std::string> live{"PENDING",   "RUNNING",    "CONFIGURING", "COMPLETING", "REQUEUED",
                                          "REQUEUE_FED", "REQUEUE_HOLD", "RESIZING",  "SUSPENDED", "STOPPED",
                                          "SIGNALING", "STAGE_OUT",  "RESV_DEL_HOLD"};
  return live.count(s) > 0;
}

std::map<long, SlurmJobState> slurm_jobs() {
  std::map<long, SlurmJobState> jobs;
  if (find_program("squeue").empty()) return jobs;
  const CommandResult r = run_command({"squeue", "--noheader", "--me", "--states=all", "--format=%i|%T|%r|%N"});
  if (r.exit_code != 0) throw Error("squeue failed: " + trimmed(r.err.empty() ? r.out : r.err));
  std::stringstream ss(r.out);
  for (std::string line; std::getline(ss, line);) {
    std::vector<std::string> f;
    std::stringstream ls(line);
    for (std::string p; std::getline(ls, p, '|');) f.push_back(trimmed(p));
    if (f.size() < 2) continue;
    if (f[0].empty() || f[0].find_first_not_of("0123456789") != std::string::npos) continue;  // array tasks: not ours
    jobs[std::stol(f[0])] = {f[1], f.size() > 2 ? f[2] : "", f.size() > 3 ? f[3] : ""};
  }
  return jobs;
}

std::string slurm_state_text(const SlurmJobState& q) {
  std::string s = q.state;
  if (q.state == "PENDING" && !q.reason.empty() && q.reason != "None") s += " (" + q.reason + ")";
  if (q.state == "RUNNING" && !q.nodes.empty()) s += " on " + q.nodes;
  return s;
}

long submitted_id(const Job& job) {
  const json j = read_json_or_empty(slurm_file(job));
  if (j.value("key", std::string()) != job.key) return 0;
  return j.value("id", 0L);
}

RunSummary run_slurm(const Plan& plan, const SlurmOptions& o) {
  const auto t0 = Clock::now();
  if (!slurm_available())
    throw Error("--backend slurm: sbatch is not on PATH (run on a machine of the cluster; docs/cluster.md)");
  const std::string program = o.program.empty() ? self_program() : o.program;
  const std::vector<bool> needed = needed_jobs(plan);
  auto queue = slurm_jobs();

  RunSummary sum;
  int submitted = 0, in_queue = 0;
  std::vector<long> ids(plan.jobs.size(), 0);
  for (std::size_t i = 0; i < plan.jobs.size(); ++i) {
    const Job& job = plan.jobs[i];
    if (!needed[i]) {
      ++sum.already_done;
      continue;
    }
    const long old = submitted_id(job);
    if (old > 0 && queue.count(old) && slurm_state_live(queue[old].state)) {
      ids[i] = old;
      ++in_queue;
      if (!o.quiet)
        std::cout << fmt::format("  {}: already submitted as Slurm job {} ({})\n", job_label(job), old, queue[old].state);
      continue;
    }
    std::vector<long> after;
    for (const std::size_t d : job.deps)
      if (ids[d] > 0) after.push_back(ids[d]);
    ids[i] = submit(plan, job, o, program, after);
    ++submitted;
    if (!o.quiet)
      std::cout << fmt::format("  {}: submitted as Slurm job {}{}{}\n", job_label(job), ids[i],
                               after.empty() ? "" : ", after " + std::to_string(after.size()) + " job(s)",
                               resumes_checkpoint(job) ? " (resumes its checkpoint)" : "")
                << std::flush;
  }
  if (!o.quiet)
    std::cout << fmt::format("sweep {}: {} jobs, {} done before, {} submitted, {} already in Slurm's queue\n", plan.name,
                             plan.jobs.size(), sum.already_done, submitted, in_queue)
              << std::flush;
  std::vector<std::size_t> watched;
  for (std::size_t i = 0; i < plan.jobs.size(); ++i)
    if (ids[i] > 0) watched.push_back(i);
  if (!o.wait || watched.empty()) {
    sum.pending = static_cast<int>(watched.size());
    sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return sum;
  }

  const StopSignalScope signals;  // Ctrl-C, SIGTERM: stop waiting; the jobs stay queued
  std::map<std::size_t, std::string> last_state;
  std::map<std::size_t, Clock::time_point> last_report;
  std::set<std::size_t> ended;
  std::set<std::size_t> failed_jobs;
  auto last_poll = Clock::now() - std::chrono::hours(1);
  while (ended.size() < watched.size() && !signals.stop_requested()) {
    if (std::chrono::duration<double>(Clock::now() - last_poll).count() < o.poll_seconds) {
      ::usleep(200 * 1000);  // a signal ends it at once (EINTR)
      continue;
    }
    last_poll = Clock::now();
    queue = slurm_jobs();
    for (const std::size_t i : watched) {
      if (ended.count(i)) continue;
      const Job& job = plan.jobs[i];
      const auto it = queue.find(ids[i]);
      const std::string state = it == queue.end() ? "" : it->second.state;
      if (slurm_state_live(state)) {
        if (o.quiet) continue;
        const std::string shown = slurm_state_text(it->second);
        const auto now = Clock::now();
        if (shown != last_state[i]) {
          last_state[i] = shown;
          last_report[i] = now;
          std::cout << fmt::format("      {}: Slurm job {} {}\n", job_label(job), ids[i], shown) << std::flush;
        } else if (state == "RUNNING" && std::chrono::duration<double>(now - last_report[i]).count() >= o.report_every) {
          last_report[i] = now;
          const Progress p = read_progress(job);
          if (p.known)
            std::cout << fmt::format("      {}: {} {:.0f}/{:.0f}\n", job_label(job), p.label, p.done, p.total) << std::flush;
        }
        continue;
      }
      // Ended, or forgotten by squeue.
      ended.insert(i);
      if (is_done(job)) {
        ++sum.ran;
        if (!o.quiet)
          std::cout << fmt::format("done  {} in {} (Slurm job {})\n", job_label(job),
                                   format_duration(read_done(job).value("seconds", 0.0)), ids[i])
                    << std::flush;
        continue;
      }
      // A job cancelled because a job it needs failed (--kill-on-invalid-dep) was skipped.
      bool behind_failure = false;
      for (const std::size_t d : job.deps) behind_failure = behind_failure || failed_jobs.count(d) > 0;
      failed_jobs.insert(i);
      if (behind_failure) {
        ++sum.skipped;
        if (!o.quiet) std::cout << fmt::format("skipped {}: a job it needs failed\n", job_label(job)) << std::flush;
      } else {
        ++sum.failed;
        std::cout << fmt::format("FAILED {} (Slurm job {} {}); the end of {}:\n{}", job_label(job), ids[i],
                                 state.empty() ? "no longer in squeue" : state, log_file(job), log_tail(job, 12))
                  << std::flush;
      }
    }
  }
  if (signals.stop_requested()) {
    sum.interrupted = true;
    sum.pending = static_cast<int>(watched.size() - ended.size());
    std::cout << fmt::format("stopped waiting: {} job{} stay in Slurm's queue (bimart sweep status {}; scancel stops them)\n",
                             sum.pending, sum.pending == 1 ? "" : "s", plan.dir)
              << std::flush;
  }
  sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return sum;
}

}  // namespace bimart::sweep
