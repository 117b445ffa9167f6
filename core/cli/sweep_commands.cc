// bimart sweep SWEEP.yaml: trains the models a sweep's rows need, generates and evaluates
// every row on the same evaluation windows, and writes the table beside the paper's
// (core/sweep/, docs/sweeps.md). bimart sweep status DIR: what is done, running, left.
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
#include "core/sweep/job_state.h"
#include "core/sweep/local_backend.h"
#include "core/sweep/plan.h"
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
  int jobs = 1;
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

std::string job_state_text(const Job& job, bool needed) {
  if (is_done(job)) return "done in " + format_duration(read_done(job).value("seconds", 0.0));
  if (!needed) return "not needed (what it feeds is done)";
  const Progress p = read_progress(job);
  std::string s = fs::exists(job.folder) ? "started" : "to run";
  if (job.kind == JobKind::Train && fs::exists(fs::path(job.folder) / "checkpoint.npz")) s = "checkpointed";
  if (p.known) s += fmt::format(" ({} {:.0f}/{:.0f})", p.label, p.done, p.total);
  return s;
}

void print_plan(const Plan& plan, int jobs, int threads) {
  const auto rates = read_rates(plan.dir);
  const int per_job = std::max(1, threads / std::max(1, jobs));
  double left = 0;
  const std::vector<bool> needed = needed_jobs(plan);
  std::cout << fmt::format("sweep {} ({}): {} jobs in {}\n", plan.name, plan.sweep_file, plan.jobs.size(), plan.dir);
  for (std::size_t i = 0; i < plan.jobs.size(); ++i) {
    const Job& j = plan.jobs[i];
    const double est = estimate_seconds(j, rates, per_job);
    if (needed[i]) left += est;
    std::string deps;
    for (const auto d : j.deps) deps += (deps.empty() ? "" : ",") + std::to_string(d + 1);
    std::cout << fmt::format("  {:>2}. {:<8} {:<34} {}  {:<28} est. {}{}\n", i + 1, job_kind_name(j.kind), j.name,
                             j.key, job_state_text(j, needed[i]), format_duration(est),
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
  if (a.backend != "local")
    throw Error("--backend " + a.backend + ": unknown backend (known: local)");
  SweepFile file = SweepFile::load(a.file);
  file.select_rows(split_commas(a.rows));
  const std::string dir = a.out.empty() ? (fs::path("out") / "sweeps" / file.name).string() : a.out;
  const Plan plan = make_plan(file, dir);
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = common_options().threads > 0 ? common_options().threads : cores;
  if (a.dry_run) {
    print_plan(plan, a.jobs, threads);
    return kExitOk;
  }
  const int lock = lock_folder(dir, a.lock_wait);
  write_plan_json(plan);
  LocalOptions lo;
  lo.jobs = a.jobs;
  lo.threads = threads;
  lo.report_every = a.report_every;
  lo.quiet = common_options().quiet > 0;
  const RunSummary s = run_local(plan, lo);
  const TableFiles t = write_table(plan);
  ::close(lock);
  std::ifstream md(fs::path(dir) / "table.md");
  std::cout << "\n" << md.rdbuf() << "\n";
  for (const auto& w : t.written) std::cout << "wrote " << w << "\n";
  if (!t.picture_note.empty()) std::cout << t.picture_note << "\n";
  std::cout << fmt::format("sweep {}: {} jobs ran, {} were done before, {} failed, {} skipped, {}\n", plan.name, s.ran,
                           s.already_done, s.failed, s.skipped, format_duration(s.seconds));
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
  int done = 0;
  const std::vector<bool> needed = needed_jobs(plan);
  for (std::size_t i = 0; i < plan.jobs.size(); ++i) {
    const Job& j = plan.jobs[i];
    done += !needed[i];
    std::cout << fmt::format("  {:>2}. {:<8} {:<34} {}  {}\n", i + 1, job_kind_name(j.kind), j.name, j.key,
                             job_state_text(j, needed[i]));
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
  cmd->add_option("--jobs", a.jobs, "jobs side by side; the threads are divided between them")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--backend", a.backend, "where jobs run: local")->capture_default_str();
  cmd->add_option("--report-every", a.report_every, "seconds between progress lines of a running job")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  cmd->add_option("--lock-wait", a.lock_wait, "seconds to wait for an earlier sweep's jobs to stop")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  CLI::App* status = cmd->add_subcommand("status", "what a sweep folder holds: each job's state, the table so far");
  status->add_option("dir", a.status_dir, "the sweep's folder")->required()->check(CLI::ExistingDirectory);
  cmd->require_subcommand(0, 1);
  out.push_back({cmd, [cmd, status] {
                   if (status->parsed()) return run_status(a.status_dir);
                   (void)cmd;
                   return run_sweep(a);
                 }});
}

}  // namespace bimart::cli
