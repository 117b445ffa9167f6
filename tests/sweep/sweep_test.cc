// bimart sweep end to end on a tiny data set with tiny models (seconds): the table, a
// second run that does nothing, a changed row that reruns only itself, a run killed with
// SIGKILL that resumes to the same table, shared models and rows, and sweep-file errors.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/sweep/sweep_file.h"
#include "tests/cli/run_bimart.h"
#include "tests/data/tiny_dataset.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

int exit_code(const test::CliRun& r) { return WIFEXITED(r.status) ? WEXITSTATUS(r.status) : -1; }

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

const fs::path& scratch() {
  static const fs::path d = [] {
    const fs::path p = fs::temp_directory_path() / ("bimart_sweep_tests_" + std::to_string(::getpid()));
    fs::remove_all(p);
    fs::create_directories(p);
    return p;
  }();
  return d;
}

std::string tiny_config(const std::string& model, int steps) {
  return "model: " + model + "\ndata: " + testing_data::tiny_dataset().dir.string() +
         "\nout: unused\nvariant: np_bps\nstride: 16\n"
         "network: {latent: 16, layers: 1, heads: 2, feedforward: 32, condition_hidden: 32, dropout: 0.1}\n"
         "diffusion: {schedule: squaredcos_cap_v2, steps: 10}\n"
         "training: {batch: 4, steps: " +
         std::to_string(steps) +
         ", lr: 1.0e-3, warmup: 2, noisy_from: 5, seed: 1, checkpoint_every: 2, validate_every: 0, log_every: 5}\n";
}

// contact maps, motion, MANO fit, one export: the rows' runs.
const char* kPipeline = R"(name: tiny_eval
stages:
  - id: sequence
    use: trajectory.sequence
    params: {path: unused.npz}
  - id: encoder
    use: encoder.np_bps
  - id: contact
    use: contact.diffusion
  - id: motion
    use: motion.diffusion
  - id: fit
    use: refine.mano_fit
  - id: guided
    use: export.sequence
    params: {path: unused.npz}
)";

std::string sweep_text(const std::string& without_c_extra = "") {
  const fs::path s = scratch();
  return "name: tiny\n"
         "base:\n"
         "  data: " + testing_data::tiny_dataset().dir.string() + "\n"
         "  split: test\n  samples: 2\n  seed: 0\n  window: 32\n"
         "  pipeline: " + (s / "tiny_eval.yaml").string() + "\n"
         "  output: guided\n"
         "models:\n"
         "  contact: {train: " + (s / "contact.yaml").string() + "}\n"
         "  motion: {train: " + (s / "motion.yaml").string() + "}\n"
         "rows:\n"
         "  - name: w C\n"
         "    section: Contact\n"
         "    models: {contact: contact, motion: motion}\n"
         "    paper: {Mul: 6.97928, Accel: 0.31398, Pen 1cm: 20.273, Con: 98.481, Art: 83.089, CM: 1.1505}\n"
         "  - name: w/o C\n"
         "    section: Contact\n"
         "    models: {contact: contact, motion: motion}\n"
         "    set: {motion.use_contact: false" + without_c_extra + "}\n"
         "    paper: {Mul: 4.4894, Accel: 0.31034, Pen 1cm: 9.4481, Con: 96.129, Art: 79.591}\n"
         "  - name: NP-BPS\n"
         "    section: Rep\n"
         "    models: {contact: contact, motion: motion}\n";
}

// The table without its wall-time column.
std::string table_numbers(const fs::path& dir) {
  std::string out;
  std::istringstream in(read(dir / "table.csv"));
  for (std::string line; std::getline(in, line);) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}

class Sweep : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    write(scratch() / "contact.yaml", tiny_config("contact", 24));
    write(scratch() / "motion.yaml", tiny_config("motion", 24));
    write(scratch() / "tiny_eval.yaml", kPipeline);
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
