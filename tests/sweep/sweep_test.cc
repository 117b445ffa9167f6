// bimart sweep end to end on a tiny data set with tiny models (seconds): the table, a
// second run that does nothing, a changed row that reruns only itself, a run killed with
// SIGKILL that resumes to the same table, shared models and rows, and sweep-file errors.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/sweep/sweep_file.h"
#include "tests/sweep/tiny_sweep.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

const fs::path& scratch() {
  static const fs::path d = test::fresh_scratch_folder("bimart_sweep_tests_");
  return d;
}

using test::exit_code;
using test::table_numbers;
std::string read(const fs::path& p) { return test::read_text(p); }
void write(const fs::path& p, const std::string& text) { test::write_text(p, text); }
std::string sweep_text(const std::string& without_c_extra = "") { return test::tiny_sweep_text(scratch(), without_c_extra); }

class Sweep : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    test::write_tiny_sweep_inputs(scratch(), 24);
    write(scratch() / "sweep.yaml", sweep_text());
    first_ = new test::CliRun(test::run_bimart("--threads 2 sweep " + (scratch() / "sweep.yaml").string() + " --out " +
                                               (scratch() / "a").string() + " --jobs 2 --report-every 1"));
  }
  static void TearDownTestSuite() {
    delete first_;
    std::error_code ec;
    fs::remove_all(scratch(), ec);
  }
  static test::CliRun* first_;
};
test::CliRun* Sweep::first_ = nullptr;

TEST_F(Sweep, RunsEveryRowAndWritesTheTable) {
  ASSERT_EQ(exit_code(*first_), 0) << first_->output;
  const fs::path a = scratch() / "a";
  // Two trainings, and two runs of the windows: "NP-BPS" is the same run as "w C".
  const auto plan = nlohmann::json::parse(read(a / "plan.json"));
  EXPECT_EQ(plan["jobs"].size(), 6u);
  EXPECT_EQ(plan["rows"][0]["generate"], plan["rows"][2]["generate"]);
  EXPECT_NE(plan["rows"][0]["generate"], plan["rows"][1]["generate"]);
  EXPECT_NE(first_->output.find("6 jobs ran, 0 were done before"), std::string::npos) << first_->output;
  const std::string md = read(a / "table.md");
  for (const char* row : {"| Contact | w C |", "| Contact | w/o C |", "| Rep | NP-BPS |"})
    EXPECT_NE(md.find(row), std::string::npos) << md;
  // Ours and the paper's side by side; w/o C has no paper CM, NP-BPS no paper numbers.
  EXPECT_TRUE(std::regex_search(md, std::regex(R"(\| w C \| [0-9.]+ / 6\.98 \|)"))) << md;
  const auto table = nlohmann::json::parse(read(a / "table.json"));
  ASSERT_EQ(table.size(), 3u);
  for (const auto& row : table) {
    for (const char* m : {"Accel", "Pen 1cm", "Pen 5mm", "Con", "Art", "Mul"})
      EXPECT_TRUE(row["ours"].contains(m)) << row.dump();
    EXPECT_EQ(row["run"], table[row["row"] == "w/o C" ? 1 : 0]["run"]);
  }
  EXPECT_TRUE(table[0]["ours"].contains("CM"));
  EXPECT_EQ(table[0]["ours"], table[2]["ours"]);
  EXPECT_TRUE(fs::exists(a / "table.csv"));
  if (std::system("command -v gnuplot > /dev/null") == 0) {
    EXPECT_TRUE(fs::exists(a / "table.png")) << read(a / "table.gp.log");
  }
  // The models trained as the configs say, in folders named by their keys.
  for (const auto& job : plan["jobs"])
    if (job["kind"] == "train") {
      EXPECT_TRUE(fs::exists(fs::path(job["folder"].get<std::string>()) / "model.npz"));
      EXPECT_NE(read(fs::path(job["folder"].get<std::string>()) / "config.yaml").find("steps: 24"), std::string::npos);
    }
}

TEST_F(Sweep, ASecondRunDoesNothing) {
  ASSERT_EQ(exit_code(*first_), 0) << first_->output;
  const std::string before = table_numbers(scratch() / "a");
  const auto r = test::run_bimart("sweep " + (scratch() / "sweep.yaml").string() + " --out " + (scratch() / "a").string());
  ASSERT_EQ(exit_code(r), 0) << r.output;
  EXPECT_NE(r.output.find("0 jobs ran, 6 were done before"), std::string::npos) << r.output;
  EXPECT_EQ(table_numbers(scratch() / "a"), before);
  const auto status = test::run_bimart("sweep status " + (scratch() / "a").string());
  ASSERT_EQ(exit_code(status), 0) << status.output;
  EXPECT_NE(status.output.find("6 of 6 jobs done"), std::string::npos) << status.output;
  EXPECT_NE(status.output.find("no sweep is running"), std::string::npos) << status.output;
}

TEST_F(Sweep, AChangedRowRerunsOnlyThatRow) {
  ASSERT_EQ(exit_code(*first_), 0) << first_->output;
  const fs::path b = scratch() / "b";
  fs::copy(scratch() / "a", b, fs::copy_options::recursive);
  write(scratch() / "sweep_b.yaml", sweep_text(", motion.cfg: 0"));
  const auto dry = test::run_bimart("sweep " + (scratch() / "sweep_b.yaml").string() + " --out " + b.string() + " --dry-run");
  ASSERT_EQ(exit_code(dry), 0) << dry.output;
  EXPECT_NE(dry.output.find("est."), std::string::npos) << dry.output;
  const auto r = test::run_bimart("sweep " + (scratch() / "sweep_b.yaml").string() + " --out " + b.string());
  ASSERT_EQ(exit_code(r), 0) << r.output;
  // The w/o C row's run and evaluation; the models and the other rows are kept.
  EXPECT_NE(r.output.find("2 jobs ran, 4 were done before"), std::string::npos) << r.output;
  const auto ta = nlohmann::json::parse(read(scratch() / "a" / "table.json"));
  const auto tb = nlohmann::json::parse(read(b / "table.json"));
  EXPECT_EQ(ta[0]["ours"], tb[0]["ours"]);
  EXPECT_NE(ta[1]["run"], tb[1]["run"]);
}

TEST_F(Sweep, ReuseTakesAnotherSweepsFinishedJobsWithTheSameKeys) {
  ASSERT_EQ(exit_code(*first_), 0) << first_->output;
  // A new folder, one row changed: the two models and the unchanged rows' evaluations come
  // from the first sweep's folder; only the changed row's run and evaluation run.
  const fs::path e = scratch() / "e";
  write(scratch() / "sweep_e.yaml", sweep_text(", motion.cfg: 0"));
  const std::string cmd = "sweep " + (scratch() / "sweep_e.yaml").string() + " --out " + e.string() + " --reuse " +
                          (scratch() / "a").string();
  const auto dry = test::run_bimart(cmd + " --dry-run");
  ASSERT_EQ(exit_code(dry), 0) << dry.output;
  EXPECT_NE(dry.output.find("would take 3 finished jobs of another sweep"), std::string::npos) << dry.output;
  EXPECT_FALSE(fs::exists(e / "evals"));  // a dry run copies nothing
  const auto r = test::run_bimart(cmd);
  ASSERT_EQ(exit_code(r), 0) << r.output;
  EXPECT_NE(r.output.find("taking 3 finished jobs"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("2 jobs ran, 4 were done before"), std::string::npos) << r.output;  // 3 taken, and the run they no longer need
  const auto ta = nlohmann::json::parse(read(scratch() / "a" / "table.json"));
  const auto te = nlohmann::json::parse(read(e / "table.json"));
  EXPECT_EQ(ta[0]["ours"], te[0]["ours"]);
  EXPECT_NE(ta[1]["run"], te[1]["run"]);
  for (const auto& entry : fs::recursive_directory_iterator(e / "models"))
    EXPECT_NE(entry.path().filename(), "checkpoint.npz");  // never the training state
}

TEST_F(Sweep, KilledWithSigkillAndRerunGivesTheSameTable) {
  ASSERT_EQ(exit_code(*first_), 0) << first_->output;
  const fs::path c = scratch() / "c";
  const std::string cmd = std::string(BIMART_CLI) + " --threads 2 sweep " + (scratch() / "sweep.yaml").string() +
                          " --out " + c.string() + " --jobs 2";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    ::execl("/bin/sh", "sh", "-c", ("exec " + cmd).c_str(), nullptr);
    ::_exit(127);
  }
  // Kill it as soon as a training has written a checkpoint (mid-training).
  bool seen = false;
  const auto t0 = std::chrono::steady_clock::now();
  while (!seen && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120)) {
    if (fs::exists(c / "models"))
      for (const auto& d : fs::directory_iterator(c / "models")) seen = seen || fs::exists(d.path() / "checkpoint.npz");
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(seen) << "no training checkpoint appeared";
  ASSERT_FALSE(fs::exists(c / "table.md"));
  const auto r = test::run_bimart("--threads 2 sweep " + (scratch() / "sweep.yaml").string() + " --out " + c.string() +
                                  " --jobs 2");
  ASSERT_EQ(exit_code(r), 0) << r.output;
  EXPECT_NE(r.output.find("resumes its checkpoint"), std::string::npos) << r.output;
  EXPECT_EQ(table_numbers(c), table_numbers(scratch() / "a"));
}

TEST_F(Sweep, RowsFlagRunsOnlyTheNamedRows) {
  ASSERT_EQ(exit_code(*first_), 0) << first_->output;
  const auto r = test::run_bimart("sweep " + (scratch() / "sweep.yaml").string() + " --out " + (scratch() / "a").string() +
                                  " --rows 'w/o C' --dry-run");
  ASSERT_EQ(exit_code(r), 0) << r.output;
  EXPECT_NE(r.output.find("4 jobs"), std::string::npos) << r.output;  // two models, one run, one evaluation
  const auto bad = test::run_bimart("sweep " + (scratch() / "sweep.yaml").string() + " --rows 'w/o G' --dry-run");
  EXPECT_EQ(exit_code(bad), 1);
  EXPECT_NE(bad.output.find("did you mean 'w/o C'"), std::string::npos) << bad.output;
}

TEST_F(Sweep, ATrainingOfTwoTasksRunsAsTwoRanksOnThisMachine) {
  ASSERT_EQ(exit_code(*first_), 0) << first_->output;
  const fs::path d = scratch() / "d";
  fs::copy(scratch() / "a", d, fs::copy_options::recursive);
  write(scratch() / "sweep_d.yaml",
        test::tiny_sweep_text(scratch(), "", "  dp: {train: " + (scratch() / "motion.yaml").string() + ", tasks_per_node: 2}\n",
                              "  - name: two tasks\n    models: {contact: contact, motion: dp}\n"));
  const auto r = test::run_bimart("--threads 2 sweep " + (scratch() / "sweep_d.yaml").string() + " --out " + d.string() +
                                  " --rows 'two tasks'");
  ASSERT_EQ(exit_code(r), 0) << r.output;
  // The contact model is shared; the two-process motion model is another model (its key).
  EXPECT_NE(r.output.find("3 jobs ran, 1 were done before"), std::string::npos) << r.output;
  const auto plan = nlohmann::json::parse(read(d / "plan.json"));
  std::string dp_folder;
  for (const auto& job : plan["jobs"])
    if (job["name"] == "dp") dp_folder = job["folder"].get<std::string>();
  ASSERT_FALSE(dp_folder.empty());
  EXPECT_FALSE(fs::exists(scratch() / "a" / "models" / fs::path(dp_folder).filename()));
  const std::string log = read(fs::path(dp_folder) / "log.txt");
  EXPECT_NE(log.find("(2 processes, MASTER_PORT="), std::string::npos) << log;
  EXPECT_TRUE(fs::exists(fs::path(dp_folder) / "model.npz"));
  const auto done = nlohmann::json::parse(read(fs::path(dp_folder) / "done.json"));
  EXPECT_EQ(done["threads"], 2);  // two processes of one thread each
  EXPECT_EQ(done["work"].get<double>(), 24.0 * 4 * 2);  // steps x batch x processes

  // One job by hand: a done one is left alone, an unknown key is an error.
  const auto again = test::run_bimart("sweep job " + d.string() + " " + fs::path(dp_folder).filename().string());
  EXPECT_EQ(exit_code(again), 0) << again.output;
  EXPECT_NE(again.output.find("is done already"), std::string::npos) << again.output;
  const auto unknown = test::run_bimart("sweep job " + d.string() + " 0123456789abcdef");
  EXPECT_EQ(exit_code(unknown), 1) << unknown.output;
  EXPECT_NE(unknown.output.find("has no job with the key '0123456789abcdef'"), std::string::npos) << unknown.output;
}

TEST(SweepBackends, UnknownBackendAndSlurmWithoutSbatchAreClearErrors) {
  const auto unknown = test::run_bimart("sweep " + std::string(BIMART_SOURCE_DIR) +
                                        "/pipelines/sweeps/table3.yaml --backend slurmm --dry-run");
  EXPECT_EQ(exit_code(unknown), 1) << unknown.output;
  EXPECT_NE(unknown.output.find("unknown backend (known: local, slurm)"), std::string::npos) << unknown.output;
  // A PATH without sbatch (the machine may have Slurm installed).
  const std::string old_path = std::getenv("PATH") != nullptr ? std::getenv("PATH") : "";
  ::setenv("PATH", "/nonexistent", 1);
  const auto r = test::run_bimart("sweep " + std::string(BIMART_SOURCE_DIR) + "/pipelines/sweeps/table3.yaml --backend slurm");
  ::setenv("PATH", old_path.c_str(), 1);
  EXPECT_EQ(exit_code(r), 1) << r.output;
  EXPECT_NE(r.output.find("--backend slurm: sbatch is not on PATH"), std::string::npos) << r.output;
}

// ---- sweep-file mistakes: file, line, nearest key ----

std::string parse_error(const std::string& text) {
  try {
    sweep::SweepFile::parse(text, "s.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

const char* kBase = "name: t\nbase: {data: d, pipeline: p.yaml}\n";

TEST(SweepFile, AMisspeltRowKeyNamesTheLineAndTheNearestKey) {
  const std::string e = parse_error(std::string(kBase) + "rows:\n  - name: a\n    modles: {motion: m}\n");
  EXPECT_NE(e.find("s.yaml:5:"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'models'"), std::string::npos) << e;
}

TEST(SweepFile, AnUnknownModelNameSuggestsTheClosest) {
  const std::string e =
      parse_error(std::string(kBase) + "models:\n  motion_a: {file: m.npz}\nrows:\n  - name: a\n    models: {motion: motion_b}\n");
  EXPECT_NE(e.find("s.yaml:7:"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'motion_a'"), std::string::npos) << e;
}

TEST(SweepFile, BaseAndModelMistakes) {
  EXPECT_NE(parse_error("name: t\nbase: {data: d, pipline: p.yaml}\nrows: [{name: a}]\n").find("did you mean 'pipeline'"),
            std::string::npos);
  EXPECT_NE(parse_error(std::string(kBase) + "models:\n  m: {file: a.npz, train: b.yaml}\nrows: [{name: a}]\n")
                .find("exactly one of 'file'"),
            std::string::npos);
  EXPECT_NE(parse_error(std::string(kBase) + "rows: [{name: a}, {name: a}]\n").find("given twice"), std::string::npos);
  EXPECT_NE(parse_error(std::string(kBase) + "rows: [{name: a, paper: {Pen1cm: 3}}]\n").find("did you mean 'Pen 1cm'"),
            std::string::npos);
  EXPECT_NE(parse_error(std::string(kBase) + "rows: [{name: a, set: {samples: 3}}]\n").find("stage.param"),
            std::string::npos);
  EXPECT_NE(parse_error("name: t\nbase: {data: d, pipeline: p.yaml}\nrows:\n  - name: a\n  - name: a\n").find("s.yaml:5:"),
            std::string::npos);
}

TEST(SweepFile, InlineModelsAndRowSelection) {
  sweep::SweepFile f = sweep::SweepFile::parse(
      std::string(kBase) + "rows:\n  - name: a\n    models: {motion: {train: m.yaml, set: {variant: u_bps}}}\n  - name: b\n",
      "s.yaml");
  ASSERT_EQ(f.models.size(), 1u);
  EXPECT_EQ(f.models[0].name, "a/motion");
  EXPECT_EQ(f.models[0].set.at(0).first, "variant");
  EXPECT_EQ(f.models[0].set.at(0).second, "u_bps");
  f.select_rows({"b"});
  ASSERT_EQ(f.rows.size(), 1u);
  EXPECT_EQ(f.rows[0].name, "b");
}

TEST(SweepFile, TheShippedTable3HasEveryRowWithThePapersNumbers) {
  const sweep::SweepFile f = sweep::SweepFile::load(std::string(BIMART_SOURCE_DIR) + "/pipelines/sweeps/table3.yaml");
  std::vector<std::string> names;
  for (const auto& r : f.rows) names.push_back(r.name);
  EXPECT_EQ(names, (std::vector<std::string>{"GT", "U-BPS", "NPA-BPS", "MANO-Rep", "NP-BPS w/o G", "NP-BPS", "w/o C",
                                             "w C", "w C + CG", "w C + CG + Opt"}));
  EXPECT_DOUBLE_EQ(f.rows[4].paper.at("Accel"), 0.28233);
  EXPECT_DOUBLE_EQ(f.rows[9].paper.at("Pen 1cm"), 2.0346);
  EXPECT_EQ(f.base.limit, 100);
  EXPECT_EQ(f.base.samples, 10);
}

}  // namespace
}  // namespace bimart
