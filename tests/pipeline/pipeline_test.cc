// The shipped pipeline (pipelines/bimart.yaml) as a user runs it, with the shipped models:
// every output of a 2-sample run, sane hands, the same files for the same seed, the user
// errors that must stop it before it writes anything, and `bimart generate` drawing a
// window's samples in one batched run. The models are young: nothing here judges quality.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <ATen/ATen.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/io/sequence.h"
#include "core/metrics/hand_vertices.h"
#include "core/object/object_io.h"
#include "core/object/object_state.h"
#include "tests/cli/run_bimart.h"

namespace fs = std::filesystem;
using namespace bimart;

namespace {

#define EXPECT_HAS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "output: " << (haystack)

const std::string kSource = BIMART_SOURCE_DIR;
const std::string kPipeline = kSource + "/pipelines/bimart.yaml";

fs::path scratch() {
  static const fs::path dir = fs::temp_directory_path() / ("bimart_pipeline_" + std::to_string(::getpid()));
  return dir;
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Every command runs in the source tree, as a user's would (the pipeline's relative paths:
// examples/, models/); the outputs go to a scratch folder.
class InSourceTree : public ::testing::Environment {
 public:
  void SetUp() override { fs::current_path(kSource); }
};
const auto* const kInSourceTree = ::testing::AddGlobalTestEnvironment(new InSourceTree);

// DDIM with 5 steps instead of the 50 DDPM steps: the same stages and files at a tenth of
// the sampling time (the suite checks the plumbing, not the samples' quality).
const std::string kFewSteps =
    " --set contact.sampler=ddim --set contact.steps=5 --set motion.sampler=ddim --set motion.steps=5";

test::CliRun run_pipeline(const std::string& args) {
  return test::run_bimart("-q run " + kPipeline + " " + args);
}

bool nothing_written(const fs::path& dir) { return !fs::exists(dir) || fs::is_empty(dir); }

// Two runs of 2 samples with one seed, shared by the tests below (the expensive part).
class ShippedPipeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    fs::remove_all(scratch());
    for (const char* name : {"a", "b"}) {
      const test::CliRun r = run_pipeline("--samples 2 --seed 5 --out " + (scratch() / name).string() + kFewSteps);
      ASSERT_EQ(exit_code(r), 0) << r.output;
      output_ += r.output;
    }
  }
  static void TearDownTestSuite() { fs::remove_all(scratch()); }
  static std::string output_;
};
std::string ShippedPipeline::output_;

const char* kFiles[] = {"sample_0.npz", "sample_1.npz", "sample_0.glb", "sample_1.glb", "viewer.html", "metrics.json"};

}  // namespace

TEST_F(ShippedPipeline, TwoSamplesWriteEveryOutput) {
  const fs::path a = scratch() / "a";
  for (const char* f : kFiles) {
    EXPECT_TRUE(fs::is_regular_file(a / f)) << f;
    EXPECT_GT(fs::file_size(a / f), 100u) << f;
    EXPECT_HAS(output_, "wrote " + (a / f).string());
  }
  EXPECT_FALSE(fs::exists(a / "sample_2.npz"));
  EXPECT_EQ(read(a / "sample_0.glb").substr(0, 4), "glTF");
  EXPECT_HAS(read(a / "viewer.html"), "sample 1");

  const nlohmann::json j = nlohmann::json::parse(read(a / "metrics.json"));
  EXPECT_EQ(j["samples"], 2);
  const auto& g = j["generated"];
  EXPECT_EQ(g["sequences"], 2);
  EXPECT_EQ(g["trajectories_with_samples"], 1);
  std::vector<std::string> names;
  for (const auto& m : g["metrics"]) names.push_back(m["name"]);
  EXPECT_EQ(names, (std::vector<std::string>{"Mul", "Accel", "Pen 1cm", "Pen 5mm", "Pen 3mm", "Depth", "Con", "Art", "CM", "Implaus", "Cavity"}));
  for (const auto& m : g["metrics"])
    if (m["name"] == "Mul" || m["name"] == "Accel" || m["name"] == "Pen 1cm" || m["name"] == "CM")
      EXPECT_TRUE(m["value"].is_number()) << m.dump();  // defined for any trajectory
  ASSERT_EQ(g["per_sequence"].size(), 2u);
  EXPECT_EQ(g["per_sequence"][1]["name"], "sample_1");
  EXPECT_EQ(g["per_sequence"][1]["file"], (a / "sample_1.npz").string());
}

TEST_F(ShippedPipeline, HandsAreFiniteAndNearTheObject) {
  for (const char* f : {"sample_0.npz", "sample_1.npz"}) {
    const std::string path = (scratch() / "a" / f).string();
    const Sequence s = read_sequence(path);
    EXPECT_EQ(s.num_frames(), 76);  // examples/trajectories/laptop_lift_open.yaml: 2.5 s at 30 fps
    EXPECT_TRUE(s.contact_maps.defined());  // the map that conditioned this sample (CM)
    const ArticulatedObject object = load_object(resolve_object_path(s, path));
    const at::Tensor v = hand_vertices(s.hands);  // [2, N, V, 3]
    ASSERT_TRUE(at::isfinite(v).all().item<bool>()) << f;
    // Each hand's centre, per frame, against the object's root position and size.
    const at::Tensor root = s.object_states.slice(1, 4, 7);  // [N, 3]
    const double radius =
        std::max(object.top.vertices.rowwise().norm().maxCoeff(), object.bottom.vertices.rowwise().norm().maxCoeff());
    const at::Tensor gap = (v.mean(2) - root.unsqueeze(0)).norm(2, -1) - radius;  // [2, N]
    EXPECT_LT(gap.max().item<double>(), 0.3) << f << ": a hand is farther than 30 cm from the object";
  }
}

TEST_F(ShippedPipeline, SameSeedSameFiles) {
  for (const char* f : kFiles) {
    if (std::string(f) == "metrics.json") continue;
    EXPECT_TRUE(read(scratch() / "a" / f) == read(scratch() / "b" / f)) << f << " differs between two runs";
  }
  // metrics.json names its folder and files; the rest must agree.
  auto strip = [](nlohmann::json j) {
    j["generated"].erase("folder");
    for (auto& s : j["generated"]["per_sequence"]) s.erase("file");
    return j;
  };
  EXPECT_EQ(strip(nlohmann::json::parse(read(scratch() / "a" / "metrics.json"))),
            strip(nlohmann::json::parse(read(scratch() / "b" / "metrics.json"))));
}

TEST_F(ShippedPipeline, GenerateDrawsAWindowsSamplesInOneRun) {
  // A one-sequence data set made of a sample of the run above.
  const fs::path data = scratch() / "data";
  fs::create_directories(data / "sequences");
  fs::copy_file(scratch() / "a" / "sample_0.npz", data / "sequences" / "s.npz");
  // The sample names its object by an absolute path (trajectory.file's object cache).
  std::ofstream(data / "manifest.json") << R"({"test": ["sequences/s.npz"]})";
  const fs::path out = scratch() / "generate";
  const test::CliRun r = test::run_bimart("-q generate " + data.string() + " --samples 2 --window 32 --out " +
                                          out.string() + " --pipeline " + kSource + "/pipelines/generate_eval.yaml" + kFewSteps);
  ASSERT_EQ(exit_code(r), 0) << r.output;
  EXPECT_HAS(r.output, "1 windows x 2 samples");
  for (const char* set : {"guided", "refined"})
    for (const char* k : {"s00", "s01"}) {
      const fs::path f = out / set / (std::string("sample_0_f022_") + k + ".npz");
      ASSERT_TRUE(fs::exists(f)) << f;
      EXPECT_EQ(read_sequence(f.string()).num_frames(), 32);
    }
  EXPECT_TRUE(fs::exists(out / "ground_truth" / "sample_0_f022.npz"));  // the middle 32 of 76 frames
  const nlohmann::json j = nlohmann::json::parse(read(out / "generate.json"));
  EXPECT_EQ(j["windows"][0]["fit_residual_mm"].size(), 2u);
  // bimart eval groups the two samples as one trajectory (Mul).
  const test::CliRun e = test::run_bimart("-q eval " + (out / "refined").string());
  ASSERT_EQ(exit_code(e), 0) << e.output;
  EXPECT_HAS(e.output, "2 sequences, 1 trajectories, 1 with several samples");

  // --resume keeps the finished window (its files untouched, its residuals in the summary)...
  const std::string again = "generate " + data.string() + " --samples 2 --window 32 --out " + out.string() +
                            " --pipeline " + kSource + "/pipelines/generate_eval.yaml" + kFewSteps + " --resume";
  const fs::path s1 = out / "refined" / "sample_0_f022_s01.npz";
  const auto written = fs::last_write_time(s1);
  const test::CliRun kept = test::run_bimart(again);
  ASSERT_EQ(exit_code(kept), 0) << kept.output;
  EXPECT_HAS(kept.output, "1 of 1 windows were already done (--resume)");
  EXPECT_EQ(fs::last_write_time(s1), written);
  EXPECT_EQ(nlohmann::json::parse(read(out / "generate.json"))["mean_fit_residual_mm"], j["mean_fit_residual_mm"]);
  // ... but runs it again when a sample file is missing, or the command differs.
  fs::remove(s1);
  const test::CliRun redo = test::run_bimart(again);
  ASSERT_EQ(exit_code(redo), 0) << redo.output;
  EXPECT_TRUE(fs::exists(s1));
  EXPECT_EQ(redo.output.find("already done"), std::string::npos) << redo.output;
  const test::CliRun other = test::run_bimart(again + " --seed 3");
  ASSERT_EQ(exit_code(other), 0) << other.output;
  EXPECT_EQ(other.output.find("already done"), std::string::npos) << other.output;
}

// User errors: exit code 1, the file named, nothing written.
TEST(PipelineErrors, MissingCheckpoint) {
  const fs::path out = scratch() / "err_checkpoint";
  const test::CliRun r = run_pipeline("--set motion.checkpoint=models/no_such_motion.npz --out " + out.string());
  EXPECT_EQ(exit_code(r), 1) << r.output;
  EXPECT_HAS(r.output, "bimart.yaml:");
  EXPECT_HAS(r.output, "no_such_motion.npz");
  EXPECT_TRUE(nothing_written(out));
}

TEST(PipelineErrors, MisspeltVariable) {
  const fs::path out = scratch() / "err_var";
  const test::CliRun r = run_pipeline("--var smples=2 --out " + out.string());
  EXPECT_EQ(exit_code(r), 1) << r.output;
  EXPECT_HAS(r.output, "bimart.yaml has no variable 'smples' (did you mean 'samples'?)");
  EXPECT_TRUE(nothing_written(out));
}

TEST(PipelineErrors, BadTrajectoryPath) {
  const fs::path out = scratch() / "err_trajectory";
  const test::CliRun r = run_pipeline("--var trajectory=examples/trajectories/no_such_file.yaml --out " + out.string());
  EXPECT_EQ(exit_code(r), 1) << r.output;
  EXPECT_HAS(r.output, "no_such_file.yaml");
  EXPECT_TRUE(nothing_written(out));
}

// An object no procedural family made — a hexagonal jewellery case written here as two OBJ
// meshes in millimetres, imported with `bimart object import` — runs through the default
// pipeline on a keyframed trajectory. Not a quality bar: it runs, the metrics are reported
// and the hands are finite and near the object.
namespace {

// A closed hexagonal prism between heights y0 and y1 (mm), outward-facing triangles; a flat
// side faces -z at z = -r cos 30°.
void write_hex_prism(const fs::path& path, double r, double y0, double y1) {
  std::ofstream out(path);
  for (double y : {y0, y1})
    for (int k = 0; k < 6; ++k) {
      const double a = M_PI / 6 + k * M_PI / 3;
      out << "v " << r * std::cos(a) << ' ' << y << ' ' << r * std::sin(a) << '\n';
    }
  for (int k = 0; k < 6; ++k) {  // sides: ring 0 (1..6) below, ring 1 (7..12) above
    const int a = 1 + k, b = 1 + (k + 1) % 6;
    out << "f " << a << ' ' << a + 6 << ' ' << b + 6 << "\nf " << a << ' ' << b + 6 << ' ' << b << '\n';
  }
  for (int k = 1; k < 5; ++k) {  // caps as fans
    out << "f 1 " << 1 + k << ' ' << 2 + k << '\n';
    out << "f 7 " << 8 + k << ' ' << 7 + k << '\n';
  }
}

}  // namespace

TEST(ImportedObject, RunsThroughTheDefaultPipeline) {
  const fs::path dir = scratch() / "imported";
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_hex_prism(dir / "base.obj", 110, 0, 70);
  write_hex_prism(dir / "lid.obj", 110, 70, 85);
  const double back = -110 * std::cos(M_PI / 6);  // the flat back side, where the hinge is
  test::CliRun r = test::run_bimart(fmt::format(
      "-q object import {0}/lid.obj {0}/base.obj --top {0}/lid.obj --pivot 0 70 {1} --axis -1 0 0 --units mm "
      "--out {0}/case",
      dir.string(), back));
  ASSERT_EQ(exit_code(r), 0) << r.output;
  // Resting on the table, then the lid opens to 80° and the case is lifted a little.
  std::ofstream(dir / "open.yaml") << "object: case\nkeys:\n"
                                      "  - {t: 0, position: [0, 0.08, 0], rotation: {euler_xyz: [0, -90, 0]}, angle: 0}\n"
                                      "  - {t: 1.0, angle: 80, position: [0, 0.12, 0.03]}\n"
                                      "  - {t: 2.0, angle: 80}\n";
  r = run_pipeline("--var trajectory=" + (dir / "open.yaml").string() + " --out " + (dir / "out").string() + kFewSteps);
  ASSERT_EQ(exit_code(r), 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(read(dir / "out" / "metrics.json"));
  for (const auto& m : j["generated"]["metrics"])
    if (m["name"] == "Con" || m["name"] == "Pen 1cm") {
      ASSERT_TRUE(m["value"].is_number()) << m.dump();
      EXPECT_GE(m["value"].get<double>(), 0.0);
      EXPECT_LE(m["value"].get<double>(), 100.0);
    }
  const std::string seq = (dir / "out" / "sample_0.npz").string();
  const Sequence s = read_sequence(seq);
  EXPECT_EQ(s.num_frames(), 61);
  const at::Tensor v = hand_vertices(s.hands);
  ASSERT_TRUE(at::isfinite(v).all().item<bool>());
  const at::Tensor root = s.object_states.slice(1, 4, 7);
  const at::Tensor gap = (v.mean(2) - root.unsqueeze(0)).norm(2, -1);  // hand centre to the case's root
  EXPECT_LT(gap.max().item<double>(), 0.45) << "a hand is far from the imported case";
}
