// bimart sweep --backend slurm against a real one-machine Slurm cluster started by the
// test (tests/sweep/slurm_cluster.sh: Debian's slurmctld, slurmd and munge): the tiny
// sweep submitted as chained batch jobs gives the same table as the local backend; a
// second submission finds the jobs already queued; a training cancelled with scancel
// mid-run resumes from its checkpoint on the next run; and a training of two tasks per
// node runs as one srun step of two ranks that train like one process on the union of
// their batches. Skipped (with the reason) without root or the Slurm packages.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/diffusion/checkpoint.h"
#include "core/diffusion/training.h"
#include "tests/diffusion/union_of_batches.h"
#include "tests/sweep/tiny_sweep.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;
using test::exit_code;
using test::read_text;

const fs::path& scratch() {
  static const fs::path d = test::fresh_scratch_folder("bimart_slurm_tests_");
  return d;
}

// The output of a shell command line (its exit code in *status).
std::string run_shell(const std::string& cmd, int* status = nullptr) {
  const test::CliRun r = test::run_shell(cmd);
  if (status != nullptr) *status = exit_code(r);
  return r.output;
}

std::string cluster_script() { return std::string(BIMART_SOURCE_DIR) + "/tests/sweep/slurm_cluster.sh"; }

class SlurmSweep : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (::geteuid() != 0) {
      skip_ = "needs root: slurmd starts the jobs as their user";
      return;
    }
    for (const char* p : {"munged", "slurmctld", "slurmd", "sbatch", "squeue", "scancel", "srun"})
      if (run_shell(std::string("command -v ") + p).empty()) {
        skip_ = std::string(p) + " is not installed (scripts/setup.sh installs Slurm)";
        return;
      }
    int status = 0;
    const std::string out = run_shell("bash " + cluster_script() + " start " + (scratch() / "cluster").string(), &status);
    std::smatch m;
    if (status != 0 || !std::regex_search(out, m, std::regex("SLURM_CONF=(\\S+)"))) {
      failure_ = "the test cluster did not start:\n" + out;
      return;
    }
    ::setenv("SLURM_CONF", m[1].str().c_str(), 1);
  }
  static void TearDownTestSuite() {
    if (skip_.empty()) run_shell("bash " + cluster_script() + " stop " + (scratch() / "cluster").string());
    std::error_code ec;
    fs::remove_all(scratch(), ec);
  }
  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    ASSERT_EQ(failure_, "");
  }
  static std::string skip_, failure_;
};
std::string SlurmSweep::skip_, SlurmSweep::failure_;

long slurm_id(const fs::path& job_folder) {
  return nlohmann::json::parse(read_text(job_folder / "slurm.json")).value("id", 0L);
}

std::string slurm_state(long id) {
  std::string s = run_shell("squeue --noheader --states=all --jobs=" + std::to_string(id) + " --format=%T");
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  return s;
}

// The folder of the model `name` in a sweep's plan.
fs::path model_folder(const fs::path& dir, const std::string& name) {
  const auto plan = nlohmann::json::parse(read_text(dir / "plan.json"));
  for (const auto& job : plan["jobs"])
    if (job["kind"] == "train" && job["name"] == name) return job["folder"].get<std::string>();
  return {};
}

// The table's first `rows` rows (and its header) without the wall-time column.
std::string first_rows(const fs::path& dir, int rows) {
  std::istringstream in(test::table_numbers(dir));
  std::string out, line;
  for (int i = 0; i <= rows && std::getline(in, line); ++i) out += line + "\n";
  return out;
}

TEST_F(SlurmSweep, ChainedBatchJobsResumeAfterScancelAndGiveTheLocalTable) {
  const fs::path s = scratch();
  test::write_tiny_sweep_inputs(s, 400, 20);
  // The data-parallel model: dropout and clipping off, so it can be checked against one
  // process on the union of the two ranks' batches (its training weights, not the EMA).
  std::string dp = test::tiny_sweep_config("motion", 20, 10);
  dp = std::regex_replace(dp, std::regex("dropout: 0\\.1"), "dropout: 0.0");
  dp = std::regex_replace(dp, std::regex("log_every: 5"), "log_every: 5, grad_clip: 0");
  test::write_text(s / "dp.yaml", dp);
  test::write_text(s / "local.yaml", test::tiny_sweep_text(s));
  test::write_text(s / "slurm.yaml",
                   test::tiny_sweep_text(s, "", "  dp: {train: " + (s / "dp.yaml").string() + ", tasks_per_node: 2}\n",
                                         "  - name: two tasks\n    section: Slurm\n    models: {contact: contact, motion: dp}\n"));

  const auto local = test::run_bimart("--threads 2 sweep " + (s / "local.yaml").string() + " --out " +
                                      (s / "local").string() + " --jobs 2");
  ASSERT_EQ(exit_code(local), 0) << local.output;

  // Everything is queued at once; a second submission finds it there.
  const fs::path out = s / "slurm";
  const std::string submit = "sweep " + (s / "slurm.yaml").string() + " --backend slurm --out " + out.string();
  const auto first = test::run_bimart(submit + " --detach");
  ASSERT_EQ(exit_code(first), 0) << first.output;
  EXPECT_NE(first.output.find("9 jobs, 0 done before, 9 submitted, 0 already in Slurm's queue"), std::string::npos)
      << first.output;
  const auto again = test::run_bimart(submit + " --detach");
  ASSERT_EQ(exit_code(again), 0) << again.output;
  EXPECT_NE(again.output.find("0 submitted, 9 already in Slurm's queue"), std::string::npos) << again.output;

  // Cancel the motion training once it has a checkpoint: it stops and checkpoints.
  const fs::path motion = model_folder(out, "motion");
  ASSERT_TRUE(fs::exists(motion / "slurm.json")) << motion << "\n" << first.output;
  const long id = slurm_id(motion);
  ASSERT_GT(id, 0);
  const auto t0 = std::chrono::steady_clock::now();
  while (!fs::exists(motion / "checkpoint.npz") && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(fs::exists(motion / "checkpoint.npz")) << slurm_state(id) << "\n" << read_text(motion / "log.txt");
  run_shell("scancel " + std::to_string(id));
  while (slurm_state(id) != "CANCELLED" && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_EQ(slurm_state(id), "CANCELLED") << read_text(motion / "log.txt");
  ASSERT_FALSE(fs::exists(motion / "done.json")) << "the training finished before it was cancelled";
  const auto status = test::run_bimart("sweep status " + out.string());
  ASSERT_EQ(exit_code(status), 0) << status.output;
  EXPECT_TRUE(std::regex_search(status.output, std::regex("checkpointed.*Slurm job " + std::to_string(id) + " CANCELLED")))
      << status.output;

  // The rerun submits what is left, the cancelled training resuming, and waits for it.
  const auto rerun = test::run_bimart(submit + " --report-every 1");
  ASSERT_EQ(exit_code(rerun), 0) << rerun.output << read_text(motion / "log.txt");
  EXPECT_NE(rerun.output.find("(resumes its checkpoint)"), std::string::npos) << rerun.output;
  EXPECT_NE(read_text(motion / "log.txt").find("--resume"), std::string::npos);
  EXPECT_EQ(first_rows(out, 3), first_rows(s / "local", 3));
  EXPECT_NE(read_text(out / "table.md").find("| Slurm | two tasks |"), std::string::npos) << read_text(out / "table.md");

  // The two-task training: one srun step of two ranks, equal to one process on the union.
  const fs::path two = model_folder(out, "dp");
  const std::string log = read_text(two / "log.txt");
  EXPECT_NE(log.find("srun --ntasks=2"), std::string::npos) << log;
  EXPECT_NE(log.find("(2 processes"), std::string::npos) << log;
  const diffusion::TrainConfig c = diffusion::load_train_config((two / "config.yaml").string());
  const diffusion::Checkpoint ck = diffusion::load_checkpoint((two / "checkpoint.npz").string());
  ASSERT_TRUE(ck.train.has_value());
  EXPECT_EQ(ck.train->step, 20);
  EXPECT_LE(diffusion::largest_parameter_difference(diffusion::train_on_union_of_batches(c, 2), ck.train->weights),
            1e-5);
}

}  // namespace
}  // namespace bimart
