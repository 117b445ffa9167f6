// bimart sweep SWEEP.yaml: trains the models a sweep's rows need, generates and evaluates
// every row on the same evaluation windows, and writes the table beside the paper's
// (core/sweep/, docs/sweeps.md) on this machine or a Slurm cluster (docs/cluster.md).
// bimart sweep status DIR: what is done, running, left. bimart sweep job DIR KEY: one job.
#include <algorithm>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "core/cli/command.h"
#include "core/cli/common_options.h"
#include "core/sweep/job_runner.h"
#include "core/sweep/job_state.h"
#include "core/sweep/local_backend.h"
#include "core/sweep/plan.h"
#include "core/sweep/slurm_backend.h"
#include "core/sweep/sweep_file.h"
#include "core/sweep/table.h"
#include "core/util/error.h"
#include "core/util/text.h"

namespace bimart::cli {
namespace {

namespace fs = std::filesystem;
using namespace bimart::sweep;

struct SweepArgs {
  std::string file, out, rows, backend = "local", status_dir;
  bool dry_run = false;
  std::vector<std::string> reuse;
  int jobs = 1;
  // --backend slurm
  std::string partition, account, time_limit, sbatch_args, bimart;
  int cpus_per_task = 0;
  bool detach = false;
  // bimart sweep job DIR KEY
  std::string job_dir, job_key;
  double report_every = 30;
  double lock_wait = 60;
};

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string p; std::getline(ss, p, ',');)
    if (!p.empty()) out.push_back(p);
  return out;
}

// One sweep per folder at a time. The lock is inherited by the jobs a sweep starts, so a
// rerun after the sweep was killed waits until its jobs have stopped (and checkpointed).
int lock_folder(const std::string& dir, double wait_seconds) {
  fs::create_directories(dir);
  const std::string path = (fs::path(dir) / "sweep.lock").string();
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT, 0644);
  if (fd < 0) throw Error("cannot open " + path);
  const auto t0 = std::chrono::steady_clock::now();
  bool told = false;
  while (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (waited >= wait_seconds) {
      ::close(fd);
      throw Error("another bimart sweep (or a job it started) still runs on " + dir + " (" + path +
                  " is locked); wait for it or stop it first");
    }
    if (!told) std::cout << "waiting for the jobs of an earlier sweep on " << dir << " to stop...\n" << std::flush;
    told = true;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  return fd;
}

bool folder_locked(const std::string& dir) {
  const std::string path = (fs::path(dir) / "sweep.lock").string();
  const int fd = ::open(path.c_str(), O_RDWR);
  if (fd < 0) return false;
  const bool busy = ::flock(fd, LOCK_EX | LOCK_NB) != 0;
  ::close(fd);
  return busy;
}

std::string job_state_text(const Job& job, bool needed, bool elsewhere = false) {
  if (is_done(job)) return "done in " + format_duration(read_done(job).value("seconds", 0.0));
  if (elsewhere) return "done in another sweep";
  if (!needed) return "not needed (what it feeds is done)";
  const Progress p = read_progress(job);
  std::string s = fs::exists(job.folder) ? "started" : "to run";
  if (resumes_checkpoint(job)) s = "checkpointed";
  if (p.known) s += fmt::format(" ({} {:.0f}/{:.0f})", p.label, p.done, p.total);
  return s;
}

// ", Slurm job 4711 RUNNING on n12" for a job submitted to Slurm; "" otherwise.
std::string slurm_text(const Job& job, const std::map<long, SlurmJobState>& queue) {
  const long id = submitted_id(job);
  if (id <= 0) return "";
  const auto it = queue.find(id);
  if (it == queue.end()) return fmt::format(", Slurm job {} (no longer in squeue)", id);
  return fmt::format(", Slurm job {} {}", id, slurm_state_text(it->second));
}

// --bimart as an absolute path ("" = this program).
std::string program_option(const SweepArgs& a) { return a.bimart.empty() ? std::string() : fs::absolute(a.bimart).string(); }

std::vector<std::string> split_spaces(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string p; ss >> p;) out.push_back(p);
  return out;
}

// `elsewhere`: jobs --reuse would take, shown and counted as done.
void print_plan(const Plan& plan, int jobs, int threads, const std::vector<std::size_t>& elsewhere) {
  const auto rates = read_rates(plan.dir);
  const int per_job = std::max(1, threads / std::max(1, jobs));
  double left = 0;
  const std::vector<bool> needed = needed_jobs(plan, elsewhere);
  std::cout << fmt::format("sweep {} ({}): {} jobs in {}\n", plan.name, plan.sweep_file, plan.jobs.size(), plan.dir);
  for (std::size_t i = 0; i < plan.jobs.size(); ++i) {
    const Job& j = plan.jobs[i];
    const double est = estimate_seconds(j, rates, per_job);
    if (needed[i]) left += est;
    std::string deps;
    for (const auto d : j.deps) deps += (deps.empty() ? "" : ",") + std::to_string(d + 1);
    std::cout << fmt::format("  {:>2}. {:<8} {:<34} {}  {:<28} est. {}{}\n", i + 1, job_kind_name(j.kind), j.name,
                             j.key,
                             job_state_text(j, needed[i],
                                            std::find(elsewhere.begin(), elsewhere.end(), i) != elsewhere.end()),
                             format_duration(est),
                             deps.empty() ? "" : "  after " + deps);
  }
  std::cout << fmt::format("rows:\n");
  for (const auto& r : plan.rows)
    std::cout << fmt::format("  {:<18} samples of job {}, {} evaluated by job {}\n", r.name, r.generate + 1, r.output,
                             r.eval + 1);
  std::cout << fmt::format("left: about {} of work, {} with {} job{} side by side ({} thread{} each)\n",
                           format_duration(left), format_duration(left / std::max(1, jobs)), jobs,
                           jobs == 1 ? "" : "s", per_job, per_job == 1 ? "" : "s");
}

int run_sweep(const SweepArgs& a) {
  if (a.file.empty()) throw Error("bimart sweep needs a sweep file (bimart sweep SWEEP.yaml) or 'status DIR'");
  if (a.backend != "local" && a.backend != "slurm")
    throw Error("--backend " + a.backend + ": unknown backend (known: local, slurm)");
  if (a.backend == "slurm" && !a.dry_run && !slurm_available())
    throw Error("--backend slurm: sbatch is not on PATH (run on a machine of the cluster; docs/cluster.md)");
  SweepFile file = SweepFile::load(a.file);
  file.select_rows(split_commas(a.rows));
  const std::string dir = a.out.empty() ? (fs::path("out") / "sweeps" / file.name).string() : a.out;
  const Plan plan = make_plan(file, dir);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = common_options().threads > 0 ? common_options().threads : cores;
  const auto elsewhere = finished_elsewhere(plan, a.reuse);
  const auto list_elsewhere = [&](const char* verb) {
    if (elsewhere.empty()) return;
    std::cout << fmt::format("{} {} finished job{} of another sweep (--reuse):\n", verb, elsewhere.size(),
                             elsewhere.size() == 1 ? "" : "s");
    for (const auto& [i, from] : elsewhere) std::cout << fmt::format("  {}  {}\n", job_label(plan.jobs[i]), from);
  };
  if (a.dry_run) {
    list_elsewhere("would take");
    std::vector<std::size_t> taken;
    for (const auto& e : elsewhere) taken.push_back(e.first);
    print_plan(plan, a.jobs, threads, taken);
    return kExitOk;
  }
  const int lock = lock_folder(dir, a.lock_wait);
  list_elsewhere("taking");
  adopt_finished(plan, elsewhere);
  write_plan_json(plan);
  RunSummary s;
  if (a.backend == "slurm") {
    SlurmOptions so;
    so.partition = a.partition;
    so.account = a.account;
    so.time_limit = a.time_limit;
    so.sbatch_args = split_spaces(a.sbatch_args);
    so.program = program_option(a);
    so.cpus_per_task = a.cpus_per_task;
    so.wait = !a.detach;
    so.report_every = a.report_every;
    so.quiet = common_options().quiet > 0;
    s = run_slurm(plan, so);
  } else {
    LocalOptions lo;
    lo.jobs = a.jobs;
    lo.threads = threads;
    lo.program = program_option(a);
    lo.report_every = a.report_every;
    lo.quiet = common_options().quiet > 0;
    s = run_local(plan, lo);
  }
  const TableFiles t = write_table(plan);
  ::close(lock);
  std::ifstream md(fs::path(dir) / "table.md");
  std::cout << "\n" << md.rdbuf() << "\n";
  for (const auto& w : t.written) std::cout << "wrote " << w << "\n";
  if (!t.picture_note.empty()) std::cout << t.picture_note << "\n";
  std::cout << fmt::format("sweep {}: {} jobs ran, {} were done before, {} failed, {} skipped, {}\n", plan.name, s.ran,
                           s.already_done, s.failed, s.skipped, format_duration(s.seconds));
  if (s.pending > 0)
    std::cout << fmt::format("{} job{} in Slurm's queue: bimart sweep status {} follows them; run the same command "
                             "again to wait for them\n",
                             s.pending, s.pending == 1 ? " is" : "s are", dir);
  if (s.interrupted) {
    std::cout << "interrupted: run the same command again to continue\n";
    return kExitInterrupted;
  }
  return s.failed > 0 || s.skipped > 0 ? kExitUserError : kExitOk;
}

int run_status(const std::string& dir) {
  const Plan plan = read_plan_json(dir);
  const bool running = folder_locked(dir);
  std::cout << fmt::format("sweep {} in {} ({}): {}\n", plan.name, dir, plan.sweep_file,
                           running ? "a sweep is running" : "no sweep is running");
  // What Slurm says of the jobs that were submitted to it.
  std::map<long, SlurmJobState> queue;
  bool submitted = false;
  for (const Job& j : plan.jobs) submitted = submitted || submitted_id(j) > 0;
  if (submitted) {
    try {
      queue = slurm_jobs();
    } catch (const Error& e) {
      std::cout << "(cannot ask Slurm: " << e.what() << ")\n";
    }
  }
  int done = 0;
  const std::vector<bool> needed = needed_jobs(plan);
  for (std::size_t i = 0; i < plan.jobs.size(); ++i) {
    const Job& j = plan.jobs[i];
    done += !needed[i];
    const std::string slurm = needed[i] ? slurm_text(j, queue) : "";
    std::cout << fmt::format("  {:>2}. {:<8} {:<34} {}  {}{}\n", i + 1, job_kind_name(j.kind), j.name, j.key,
                             job_state_text(j, needed[i]), slurm);
    // A Slurm job that ended without finishing: the end of its log says why.
    const long id = submitted_id(j);
    if (needed[i] && id > 0 && !(queue.count(id) && slurm_state_live(queue.at(id).state))) {
      std::istringstream tail(log_tail(j, 3));
      for (std::string line; std::getline(tail, line);) std::cout << "        | " << line << "\n";
    }
  }
  std::cout << fmt::format("{} of {} jobs done\n\n", done, plan.jobs.size());
  std::cout << table_markdown(plan, collect_table(plan));
  return kExitOk;
}

}  // namespace

void add_sweep_commands(CLI::App& app, Commands& out) {
  static SweepArgs a;
  CLI::App* cmd = app.add_subcommand(
      "sweep", "train, generate and evaluate the rows of an ablation table; resumable (docs/sweeps.md)");
  cmd->add_option("sweep_file", a.file, "the sweep file (e.g. pipelines/sweeps/table3.yaml)");
  cmd->add_option("--out", a.out, "the sweep's folder (default: out/sweeps/<name>)");
  cmd->add_option("--rows", a.rows, "only these rows (comma-separated names)");
  cmd->add_flag("--dry-run", a.dry_run, "print the jobs, what is done, and time estimates; run nothing");
  cmd->add_option("--reuse", a.reuse,
                  "another sweep's folder: its finished trainings and evaluations with the same keys are copied, "
                  "not redone (repeatable)")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--jobs", a.jobs, "jobs side by side; the threads are divided between them")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--backend", a.backend, "where jobs run: local (this machine) or slurm (docs/cluster.md)")
      ->capture_default_str();
  cmd->add_option("--partition", a.partition, "slurm: sbatch --partition");
  cmd->add_option("--account", a.account, "slurm: sbatch --account");
  cmd->add_option("--time", a.time_limit, "slurm: sbatch --time, each job's time limit (e.g. 12:00:00)");
  cmd->add_option("--cpus-per-task", a.cpus_per_task,
                  "slurm: CPUs (threads) of each job whose model sets no cpus_per_task (0 = Slurm's default)")
      ->check(CLI::Range(0, 4096));
  cmd->add_option("--sbatch-args", a.sbatch_args, "slurm: more sbatch options, e.g. \"--qos=high --mem=8G\"");
  cmd->add_flag("--detach", a.detach, "slurm: submit and return; the jobs run on (bimart sweep status follows them)");
  cmd->add_option("--bimart", a.bimart, "the bimart program the jobs run (default: this one)");
  cmd->add_option("--report-every", a.report_every, "seconds between progress lines of a running job")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  cmd->add_option("--lock-wait", a.lock_wait, "seconds to wait for an earlier sweep's jobs to stop")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  CLI::App* status = cmd->add_subcommand("status", "what a sweep folder holds: each job's state, the table so far");
  status->add_option("dir", a.status_dir, "the sweep's folder")->required()->check(CLI::ExistingDirectory);
  CLI::App* job = cmd->add_subcommand(
      "job", "run one job of a planned sweep to its end (what the backends start; docs/sweeps.md)");
  job->add_option("dir", a.job_dir, "the sweep's folder (holds plan.json)")->required()->check(CLI::ExistingDirectory);
  job->add_option("key", a.job_key, "the job's key (bimart sweep status DIR lists them)")->required();
  cmd->require_subcommand(0, 1);
  out.push_back({cmd, [cmd, status, job] {
                   if (status->parsed()) return run_status(a.status_dir);
                   if (job->parsed()) {
                     JobRunOptions jo;
                     jo.program = program_option(a);
                     const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
                     jo.threads = common_options().threads > 0 ? common_options().threads : cores;
                     return run_job(read_plan_json(a.job_dir), a.job_key, jo);
                   }
                   (void)cmd;
                   return run_sweep(a);
                 }});
}

}  // namespace bimart::cli
