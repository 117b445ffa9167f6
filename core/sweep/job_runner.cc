#include "core/sweep/job_runner.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <map>

#include <fmt/format.h>

#include "core/sweep/job_state.h"
#include "core/util/atomic_file.h"
#include "core/util/error.h"
#include "core/util/interrupt.h"
#include "core/util/subprocess.h"
#include "core/util/text.h"

namespace bimart::sweep {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// A free TCP port on loopback for rank 0's store (the kernel's choice; another program
// could take it before rank 0 binds it, which the ranks then report as a join error).
int free_loopback_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw Error(std::string("cannot find a free port: ") + std::strerror(errno));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    ::close(fd);
    throw Error(std::string("cannot find a free port: ") + std::strerror(errno));
  }
  ::close(fd);
  return ntohs(a.sin_port);
}

std::string now_text() {
  const std::time_t now = std::time(nullptr);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S", std::localtime(&now));
  return when;
}

}  // namespace

std::string self_program() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error("cannot find this program's path (/proc/self/exe): " + ec.message());
  return p.string();
}

bool resumes_checkpoint(const Job& job) {
  return job.kind == JobKind::Train && fs::exists(fs::path(job.folder) / "checkpoint.npz");
}

int job_processes(const Job& job) {
  return job.kind == JobKind::Train ? std::max(1, job.nodes) * std::max(1, job.tasks_per_node) : 1;
}

std::vector<std::string> job_command(const Job& job, const std::string& program, int threads) {
  std::vector<std::string> argv{program, "--threads", std::to_string(std::max(1, threads))};
  argv.insert(argv.end(), job.args.begin(), job.args.end());
  if (resumes_checkpoint(job)) argv.push_back("--resume");
  return argv;
}

int run_job(const Plan& plan, const std::string& key, const JobRunOptions& o) {
  std::size_t index = plan.jobs.size();
  for (std::size_t i = 0; i < plan.jobs.size(); ++i)
    if (plan.jobs[i].key == key) index = i;
  if (index == plan.jobs.size()) throw Error("sweep " + plan.dir + " has no job with the key '" + key + "'");
  const Job& job = plan.jobs[index];
  const std::string label = job_label(job);
  if (is_done(job)) {
    std::cout << label << " (" << key << ") is done already\n";
    return 0;
  }
  for (const std::size_t d : job.deps)
    if (!is_done(plan.jobs.at(d)))
      throw Error(fmt::format("{} needs {} {} ({}) first, which is not done", label, job_kind_name(plan.jobs[d].kind),
                              plan.jobs[d].name, plan.jobs[d].key));

  fs::create_directories(job.folder);
  fs::remove(progress_file(job));  // an earlier run's
  if (job.kind == JobKind::Train) {
    const fs::path config = fs::path(job.folder) / "config.yaml";
    if (!job.config_text.empty())
      write_file_atomically(config.string(), [&](std::ostream& out) { out << job.config_text; });
    else if (!fs::exists(config))
      throw Error(plan.dir + "/plan.json holds no config for " + label + ": run bimart sweep again to rewrite it");
  }

  const std::string program = o.program.empty() ? self_program() : o.program;
  const int processes = job_processes(job);
  const bool in_slurm = std::getenv("SLURM_JOB_ID") != nullptr;
  // Slurm gives every task its own CPUs; on this machine the ranks share the job's threads.
  const int threads = in_slurm ? std::max(1, o.threads) : std::max(1, o.threads / processes);
  const std::vector<std::string> command = job_command(job, program, threads);
  std::vector<std::vector<std::string>> argvs;
  std::vector<std::map<std::string, std::string>> envs;
  const std::string progress = progress_file(job);
  std::string how;
  if (processes == 1) {
    argvs.push_back(command);
    envs.push_back({{"BIMART_PROGRESS_FILE", progress}});
  } else if (in_slurm) {
    // One step of all the job's tasks; a task that fails ends the others.
    std::vector<std::string> srun{"srun",
                                  "--ntasks=" + std::to_string(processes),
                                  "--nodes=" + std::to_string(std::max(1, job.nodes)),
                                  "--ntasks-per-node=" + std::to_string(std::max(1, job.tasks_per_node)),
                                  "--kill-on-bad-exit=1"};
    if (job.cpus_per_task > 0) srun.push_back("--cpus-per-task=" + std::to_string(job.cpus_per_task));
    srun.insert(srun.end(), command.begin(), command.end());
    argvs.push_back(srun);
    envs.push_back({{"BIMART_PROGRESS_FILE", progress}});
    how = fmt::format(" ({} processes, one srun step)", processes);
  } else {
    const int port = free_loopback_port();
    for (int r = 0; r < processes; ++r) {
      argvs.push_back(command);
      std::map<std::string, std::string> env{{"WORLD_SIZE", std::to_string(processes)},
                                             {"RANK", std::to_string(r)},
                                             {"MASTER_ADDR", "127.0.0.1"},
                                             {"MASTER_PORT", std::to_string(port)}};
      if (r == 0) env["BIMART_PROGRESS_FILE"] = progress;
      envs.push_back(env);
    }
    how = fmt::format(" ({} processes, MASTER_PORT={})", processes, port);
  }
  std::cout << fmt::format("==== {} {}{}\n", now_text(), join(argvs.front(), " "), how) << std::flush;

  const StopSignalScope signals;  // Ctrl-C, SIGTERM: stop the children first

  const auto t0 = Clock::now();
  std::map<pid_t, int> alive;  // pid -> rank
  for (std::size_t r = 0; r < argvs.size(); ++r) alive[start_child(argvs[r], envs[r])] = static_cast<int>(r);
  bool forwarded = false, failed = false;
  std::string why;
  ProgressWatch watch;  // for the rate recorded at the end
  auto last_look = Clock::now();
  while (!alive.empty()) {
    if (signals.stop_requested() && !forwarded) {
      forwarded = true;
      for (const auto& [pid, r] : alive) ::kill(pid, SIGTERM);
    }
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid > 0 && alive.count(pid)) {
      const int rank = alive[pid];
      alive.erase(pid);
      if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0) && !failed) {
        failed = true;
        why = exit_status_text(status);
        if (processes > 1) why = fmt::format("process {} ended with {}", rank, why);
        // One rank gone: the others would wait for it until their timeout.
        if (!forwarded)
          for (const auto& [p, r] : alive) ::kill(p, SIGTERM);
      }
      continue;
    }
    if (pid < 0 && errno == ECHILD) break;
    if (Clock::now() - last_look > std::chrono::seconds(1)) {
      watch.look(job);
      last_look = Clock::now();
    }
    ::usleep(100 * 1000);  // a signal ends it at once (EINTR), so SIGTERM reaches the children without delay
  }
  watch.look(job);
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();

  if (!failed && fs::exists(job.result)) {
    mark_done(job, seconds, threads * processes);
    record_rate(plan.dir, job.rate_key, watch.work_per_thread(job, threads, processes));
    std::cout << fmt::format("==== {} done: {} in {}\n", now_text(), label, format_duration(seconds)) << std::flush;
    return 0;
  }
  if (signals.stop_requested()) {
    std::cout << fmt::format("==== {} stopped: {} (a rerun continues it)\n", now_text(), label) << std::flush;
    return 130;
  }
  if (!failed) why = "it left no " + job.result;
  std::cout << fmt::format("==== {} failed: {} ({})\n", now_text(), label, why) << std::flush;
  return 1;
}

}  // namespace bimart::sweep
