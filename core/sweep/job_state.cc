#include "core/sweep/job_state.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>

#include "core/util/atomic_file.h"
#include "core/util/error.h"

namespace bimart::sweep {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

}  // namespace

json read_json_or_empty(const std::string& p) {
  std::ifstream in(p);
  if (!in) return json::object();
  json j = json::parse(in, nullptr, false);
  return j.is_discarded() ? json::object() : j;
}

namespace {

// Work units per second with one thread, measured on the 2-core AMD EPYC of
// docs/performance.md with the shipped sizes; used until a sweep has measured its own.
double default_rate(const Job& job) {
  switch (job.kind) {
    case JobKind::Train: return 70;     // windows/s (latent 128, one thread; docs/training.md)
    case JobKind::Generate:             // window-samples/s: 2621 s for 100 × 10 at one thread
      return job.rate_key.find("generate_eval.yaml") != std::string::npos ? 0.2 : 0.38;  // with the refinement: ~2×
    case JobKind::Eval: return 8;       // sequences/s
  }
  return 1;
}

}  // namespace

std::string done_file(const Job& job) { return (fs::path(job.folder) / "done.json").string(); }
std::string log_file(const Job& job) { return (fs::path(job.folder) / "log.txt").string(); }
std::string progress_file(const Job& job) { return (fs::path(job.folder) / "progress.json").string(); }

json read_done(const Job& job) { return read_json_or_empty(done_file(job)); }

bool is_done(const Job& job) {
  const json d = read_done(job);
  return d.value("key", std::string()) == job.key && fs::exists(job.result);
}

std::vector<std::pair<std::size_t, std::string>> finished_elsewhere(const Plan& plan,
                                                                    const std::vector<std::string>& sweeps) {
  std::vector<std::pair<std::size_t, std::string>> found;
  for (std::size_t i = 0; i < plan.jobs.size(); ++i) {
    const Job& job = plan.jobs[i];
    if (job.kind == JobKind::Generate || is_done(job)) continue;
    const fs::path rel = fs::path(job.folder).lexically_relative(plan.dir);
    const fs::path result = fs::path(job.result).lexically_relative(job.folder);
    for (const std::string& other : sweeps) {
      std::error_code ec;
      if (fs::equivalent(other, plan.dir, ec)) continue;
      Job there = job;
      there.folder = (fs::path(other) / rel).string();
      there.result = (fs::path(there.folder) / result).string();
      if (!is_done(there)) continue;
      found.emplace_back(i, there.folder);
      break;
    }
  }
  return found;
}

void adopt_finished(const Plan& plan, const std::vector<std::pair<std::size_t, std::string>>& found) {
  for (const auto& [i, from] : found) {
    const Job& job = plan.jobs[i];
    fs::create_directories(job.folder);
    for (const auto& entry : fs::directory_iterator(from)) {
      const std::string name = entry.path().filename().string();
      if (!entry.is_regular_file() || name == "done.json" || name == "checkpoint.npz") continue;
      fs::copy_file(entry.path(), fs::path(job.folder) / name, fs::copy_options::overwrite_existing);
    }
    fs::copy_file(fs::path(from) / "done.json", done_file(job), fs::copy_options::overwrite_existing);
  }
}

std::vector<bool> needed_jobs(const Plan& plan, const std::vector<std::size_t>& done_elsewhere) {
  const std::size_t n = plan.jobs.size();
  std::vector<std::vector<std::size_t>> dependents(n);
  for (std::size_t i = 0; i < n; ++i)
    for (const std::size_t d : plan.jobs[i].deps) dependents.at(d).push_back(i);
  std::vector<bool> done(n), needed(n, false);
  for (std::size_t i = 0; i < n; ++i) done[i] = is_done(plan.jobs[i]);
  for (const std::size_t i : done_elsewhere) done.at(i) = true;
  // Jobs come dependencies first, so dependents are decided before the jobs they need.
  for (std::size_t k = n; k-- > 0;) {
    if (done[k]) continue;
    bool wanted = dependents[k].empty();
    for (const std::size_t d : dependents[k]) wanted = wanted || needed[d];
    needed[k] = wanted;
  }
  return needed;
}

std::string utc_now_text() {
  const std::time_t now = std::time(nullptr);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return when;
}

void mark_done(const Job& job, double seconds, int threads) {
  const std::string when = utc_now_text();
  const json d{{"key", job.key},     {"kind", job_kind_name(job.kind)},
               {"name", job.name},   {"seconds", seconds},
               {"threads", threads}, {"work", job.work},
               {"unit", job.unit},   {"rate", seconds > 0 ? job.work / seconds : 0.0},
               {"finished", when}};
  write_file_atomically(done_file(job), [&](std::ostream& o) { o << d.dump(2) << "\n"; });
}

double thread_speedup(int threads) {
  // Two threads do not make one job twice as fast (docs/performance.md): count the second
  // and later threads at 60 %.
  return 1.0 + 0.6 * std::max(0, threads - 1);
}

Progress ProgressWatch::look(const Job& job) {
  const Progress p = read_progress(job);
  if (!p.known) return p;
  const auto now = std::chrono::steady_clock::now();
  if (first_done_ < 0 || p.label != label_) {
    label_ = p.label;
    first_done_ = last_done_ = p.done;
    first_seen_ = last_seen_ = now;
  }
  if (p.done != last_done_) {
    last_done_ = p.done;
    last_seen_ = now;
  }
  total_ = p.total;
  return p;
}

double ProgressWatch::rate() const {
  const double dt = std::chrono::duration<double>(last_seen_ - first_seen_).count();
  return first_done_ >= 0 && last_done_ > first_done_ && dt > 1 ? (last_done_ - first_done_) / dt : 0;
}

double ProgressWatch::work_per_thread(const Job& job, int threads, int processes) const {
  if (!(total_ > 0)) return 0;
  return rate() * job.work / total_ / thread_speedup(threads) / std::max(1, processes);
}

Progress read_progress(const Job& job) {
  const json j = read_json_or_empty(progress_file(job));
  Progress p;
  if (!j.contains("done") || !j.contains("total")) return p;
  p.label = j.value("label", std::string());
  p.done = j["done"].get<double>();
  p.total = j["total"].get<double>();
  p.known = true;
  return p;
}

std::string log_tail(const Job& job, int lines) {
  std::ifstream in(log_file(job));
  std::deque<std::string> last;
  for (std::string l; std::getline(in, l);) {
    // A progress bar redrawn with \r: keep what the terminal would show.
    if (const auto cr = l.rfind('\r'); cr != std::string::npos) l = l.substr(cr + 1);
    last.push_back(l);
    if (static_cast<int>(last.size()) > lines) last.pop_front();
  }
  std::string out;
  for (const auto& l : last) out += l + "\n";
  return out;
}

std::map<std::string, double> read_rates(const std::string& dir) {
  std::map<std::string, double> r;
  const json j = read_json_or_empty((fs::path(dir) / "rates.json").string());
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.value().is_number()) r[it.key()] = it.value().get<double>();
  return r;
}

void record_rate(const std::string& dir, const std::string& rate_key, double per_thread) {
  if (!(per_thread > 0) || !std::isfinite(per_thread)) return;
  json j = read_json_or_empty((fs::path(dir) / "rates.json").string());
  j[rate_key] = per_thread;
  write_file_atomically((fs::path(dir) / "rates.json").string(), [&](std::ostream& o) { o << j.dump(2) << "\n"; });
}

double estimate_seconds(const Job& job, const std::map<std::string, double>& rates, int threads) {
  const auto it = rates.find(job.rate_key);
  const double per_thread = it != rates.end() ? it->second : default_rate(job);
  const double speed = per_thread * thread_speedup(threads);
  return job.work / std::max(speed, 1e-9);
}

void write_plan_json(const Plan& plan) {
  json j;
  j["sweep_file"] = plan.sweep_file;
  j["name"] = plan.name;
  j["jobs"] = json::array();
  for (const auto& job : plan.jobs)
    j["jobs"].push_back({{"kind", job_kind_name(job.kind)},
                         {"name", job.name},
                         {"key", job.key},
                         {"folder", job.folder},
                         {"args", job.args},
                         {"deps", job.deps},
                         {"result", job.result},
                         {"work", job.work},
                         {"unit", job.unit},
                         {"rate_key", job.rate_key},
                         {"nodes", job.nodes},
                         {"tasks_per_node", job.tasks_per_node},
                         {"cpus_per_task", job.cpus_per_task},
                         {"config", job.config_text}});
  j["rows"] = json::array();
  for (const auto& r : plan.rows)
    j["rows"].push_back({{"name", r.name},
                         {"section", r.section},
                         {"output", r.output},
                         {"generate", r.generate},
                         {"eval", r.eval},
                         {"paper", r.paper}});
  write_file_atomically((fs::path(plan.dir) / "plan.json").string(), [&](std::ostream& o) { o << j.dump(2) << "\n"; });
}

Plan read_plan_json(const std::string& dir) {
  const fs::path p = fs::path(dir) / "plan.json";
  if (!fs::exists(p)) throw Error(dir + " holds no sweep (no plan.json): run bimart sweep SWEEP.yaml --out " + dir);
  const json j = read_json_or_empty(p.string());
  if (!j.contains("jobs")) throw Error(p.string() + " is not a sweep plan");
  Plan plan;
  plan.dir = dir;
  plan.sweep_file = j.value("sweep_file", std::string());
  plan.name = j.value("name", std::string());
  for (const auto& o : j["jobs"]) {
    Job job;
    const std::string kind = o.value("kind", std::string());
    job.kind = kind == "generate" ? JobKind::Generate : kind == "eval" ? JobKind::Eval : JobKind::Train;
    job.name = o.value("name", std::string());
    job.key = o.value("key", std::string());
    job.folder = o.value("folder", std::string());
    job.args = o.value("args", std::vector<std::string>());
    job.deps = o.value("deps", std::vector<std::size_t>());
    job.result = o.value("result", std::string());
    job.work = o.value("work", 0.0);
    job.unit = o.value("unit", std::string());
    job.rate_key = o.value("rate_key", std::string());
    job.nodes = o.value("nodes", 1);
    job.tasks_per_node = o.value("tasks_per_node", 1);
    job.cpus_per_task = o.value("cpus_per_task", 0);
    job.config_text = o.value("config", std::string());
    plan.jobs.push_back(job);
  }
  for (const auto& o : j.value("rows", json::array())) {
    RowPlan r;
    r.name = o.value("name", std::string());
    r.section = o.value("section", std::string());
    r.output = o.value("output", std::string());
    r.generate = o.value("generate", std::size_t{0});
    r.eval = o.value("eval", std::size_t{0});
    r.paper = o.value("paper", std::map<std::string, double>());
    plan.rows.push_back(r);
  }
  return plan;
}

}  // namespace bimart::sweep
