// The baselines (docs/baselines.md) end to end on the tiny data set: their training configs,
// tiny models that train, save, load and sample through their pipelines to sequence files
// `bimart eval` reads, their stages in `bimart plugins`, a baseline's model refused by the
// method's stages and the other way round (naming both), and OMOMO-B's contact constraint on
// known geometry.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <ATen/ATen.h>

#include "core/diffusion/checkpoint.h"
#include "core/diffusion/model_kind.h"
#include "core/diffusion/representation.h"
#include "core/diffusion/training.h"
#include "core/features/mano_representation.h"
#include "core/io/sequence.h"
#include "core/object/object_state.h"
#include "core/object/families/families.h"
#include "plugins/cams_b/manipulation_stages.h"
#include "plugins/omomo_b/joint_contact.h"
#include "tests/cli/run_bimart.h"
#include "tests/data/tiny_dataset.h"
#include "tests/diffusion/tiny_train_config.h"
#include "tests/error_of.h"

namespace bimart::diffusion {
namespace {

namespace fs = std::filesystem;
using test::error_of;
using test::exit_code;

#define EXPECT_HAS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "output: " << (haystack)

const std::string kSource = BIMART_SOURCE_DIR;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("bimart_baselines_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

test::CliRun bimart_in_source(const std::string& args) { return test::run_bimart("-q " + args); }

// A tiny model of one kind (a few seconds): 3 steps on the tiny data set.
fs::path tiny_model(const std::string& name, const std::string& representation, const std::string& condition) {
  const fs::path dir = scratch(name);
  TrainConfig c = tiny_train_config(dir, "motion");
  c.representation = representation;
  c.condition = condition;
  c.network.sample_size = motion_sample_size(representation);
  c.network.contact_condition_size = condition_size(condition);
  c.export_path = (dir / "model.npz").string();
  c.steps = 3;
  c.lr = 1e-3;
  c.warmup = 1;
  c.validate_every = 3;
  c.validation_windows = 2;
  c.log_every = 1;
  c.seed = 5;
  TrainOptions quiet;
  quiet.progress = false;
  const TrainResult r = train(c, quiet);
  EXPECT_TRUE(r.finished);
  EXPECT_TRUE(std::isfinite(r.last_loss)) << name;
  return dir / "model.npz";
}

const fs::path& mdm_b_model() {
  static const fs::path m = tiny_model("mdm_b", kManoRepresentation, kNoCondition);
  return m;
}
const fs::path& omomo_joints_model() {
  static const fs::path m = tiny_model("omomo_joints", kJointsRepresentation, kNoCondition);
  return m;
}
const fs::path& omomo_hands_model() {
  static const fs::path m = tiny_model("omomo_hands", kManoRepresentation, kJointsCondition);
  return m;
}

TEST(Baselines, ShippedTrainingConfigsSetTheModelKinds) {
  struct Case {
    const char* file;
    int sample, condition;
    const char* stage;
  };
  for (const Case& k : {Case{"mdm_b.yaml", 294, 0, "motion.mdm_b"}, Case{"omomo_b_joints.yaml", 96, 0, "joints.omomo_b"},
                        Case{"omomo_b_hands.yaml", 294, 96, "motion.omomo_b"}}) {
    const TrainConfig c = load_train_config(kSource + "/models/baselines/" + k.file);
    EXPECT_EQ(c.network.sample_size, k.sample) << k.file;
    EXPECT_EQ(c.network.contact_condition_size, k.condition) << k.file;
    ModelInfo info;
    info.network = c.network;
    info.representation = c.representation;
    info.condition = c.condition;
    EXPECT_EQ(sampling_stage(info), k.stage) << k.file;
  }
}

TEST(Baselines, ConditionMistakesNameTheFileAndLine) {
  const fs::path dir = scratch("config");
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string bad = error_of([&] { load_train_config(write("a.yaml", "model: motion\ndata: d\nout: o\ncondition: text\n")); });
  EXPECT_HAS(bad, "a.yaml:4");
  EXPECT_HAS(bad, "contact, none or joints");
  const std::string contact =
      error_of([&] { load_train_config(write("b.yaml", "model: contact\ndata: d\nout: o\ncondition: none\n")); });
  EXPECT_HAS(contact, "b.yaml:4");
  EXPECT_HAS(contact, "motion model only");
  const std::string self = error_of([&] {
    load_train_config(write("c.yaml", "model: motion\ndata: d\nout: o\nrepresentation: joints\ncondition: joints\n"));
  });
  EXPECT_HAS(self, "cannot be conditioned on them");
}

TEST(Baselines, CheckpointsKeepTheirConditionAndOlderOnesReadAsContact) {
  const Checkpoint m = load_checkpoint(mdm_b_model().string());
  EXPECT_EQ(m.info.condition, "none");
  EXPECT_EQ(m.info.representation, "mano");
  EXPECT_EQ(m.info.network.contact_condition_size, 0);
  EXPECT_EQ(load_checkpoint(omomo_hands_model().string()).info.condition, "joints");
  EXPECT_EQ(load_checkpoint(kSource + "/models/motion.npz").info.condition, "contact");  // written before
}

TEST(Baselines, MdmBSamplesThroughItsPipelineToSequencesBimartEvalReads) {
  const fs::path out = scratch("mdm_b_run");
  const test::CliRun r = bimart_in_source(
      "generate " + testing_data::tiny_dataset().dir.string() + " --samples 2 --window 32 --out " + out.string() +
      " --pipeline " + kSource + "/pipelines/generate_eval_mdm_b.yaml --set motion.checkpoint=" +
      mdm_b_model().string() + " --set motion.sampler=ddim --set motion.steps=3");
  ASSERT_EQ(exit_code(r), 0) << r.output;
  EXPECT_HAS(r.output, "1 windows x 2 samples");
  for (const char* k : {"s00", "s01"}) {
    const fs::path f = out / "guided" / (std::string("test_d_f024_") + k + ".npz");
    ASSERT_TRUE(fs::exists(f)) << f;
    const Sequence s = read_sequence(f.string());
    EXPECT_EQ(s.num_frames(), 32);
    EXPECT_TRUE(at::isfinite(s.hands.hands[0].trans).all().item<bool>());
  }
  const test::CliRun e = bimart_in_source("eval " + (out / "guided").string());
  ASSERT_EQ(exit_code(e), 0) << e.output;
  EXPECT_HAS(e.output, "2 sequences, 1 trajectories");
}

TEST(Baselines, OmomoBSamplesJointsThenHandsToSequencesBimartEvalReads) {
  const fs::path out = scratch("omomo_b_run");
  const test::CliRun r = bimart_in_source(
      "generate " + testing_data::tiny_dataset().dir.string() + " --samples 2 --window 32 --out " + out.string() +
      " --pipeline " + kSource + "/pipelines/generate_eval_omomo_b.yaml --set joints.checkpoint=" +
      omomo_joints_model().string() + " --set motion.checkpoint=" + omomo_hands_model().string() +
      " --set joints.sampler=ddim --set joints.steps=3 --set motion.sampler=ddim --set motion.steps=3");
  ASSERT_EQ(exit_code(r), 0) << r.output;
  const fs::path f = out / "guided" / "test_d_f024_s01.npz";
  ASSERT_TRUE(fs::exists(f)) << f;
  EXPECT_EQ(read_sequence(f.string()).num_frames(), 32);
  const test::CliRun e = bimart_in_source("eval " + (out / "guided").string());
  ASSERT_EQ(exit_code(e), 0) << e.output;
  EXPECT_HAS(e.output, "2 sequences, 1 trajectories");
}

TEST(Baselines, StagesAreListedAndRefuseEachOthersModelsNamingBoth) {
  const test::CliRun p = bimart_in_source("plugins");
  for (const char* stage : {"motion.mdm_b", "joints.omomo_b", "motion.omomo_b"}) EXPECT_HAS(p.output, stage);
  const std::string data = testing_data::tiny_dataset().dir.string();
  const fs::path out = scratch("refuse");
  // MDM-B's model given to the MANO-Rep stage.
  const test::CliRun a = bimart_in_source("generate " + data + " --window 32 --out " + (out / "a").string() +
                                          " --pipeline " + kSource + "/pipelines/generate_eval_mano_rep.yaml" +
                                          " --set motion.checkpoint=" + mdm_b_model().string());
  EXPECT_EQ(exit_code(a), 1) << a.output;
  EXPECT_HAS(a.output, "motion.diffusion_mano cannot sample");
  EXPECT_HAS(a.output, "it is an MDM-B model");
  EXPECT_HAS(a.output, "sampled by motion.mdm_b");
  // The method's motion model given to MDM-B's stage.
  const test::CliRun b = bimart_in_source("generate " + data + " --window 32 --out " + (out / "b").string() +
                                          " --pipeline " + kSource + "/pipelines/generate_eval_mdm_b.yaml" +
                                          " --set motion.checkpoint=" + kSource + "/models/motion.npz");
  EXPECT_EQ(exit_code(b), 1) << b.output;
  EXPECT_HAS(b.output, "motion.mdm_b cannot sample");
  EXPECT_HAS(b.output, "the method's motion model");
  EXPECT_HAS(b.output, "sampled by motion.diffusion");
  // OMOMO-B's two models swapped.
  const test::CliRun c = bimart_in_source(
      "generate " + data + " --window 32 --out " + (out / "c").string() + " --pipeline " + kSource +
      "/pipelines/generate_eval_omomo_b.yaml --set joints.checkpoint=" + omomo_hands_model().string() +
      " --set motion.checkpoint=" + omomo_joints_model().string());
  EXPECT_EQ(exit_code(c), 1) << c.output;
  EXPECT_HAS(c.output, "joints.omomo_b cannot sample");
  EXPECT_HAS(c.output, "sampled by motion.omomo_b");
}

TEST(Baselines, JointContactPutsNearJointsOnTheSurfaceAndLeavesFarOnes) {
  const ArticulatedObject object = make_object("box", 0);
  const at::Tensor states = at::zeros({3, 7});
  const JointContact contact(object, states, 0.02);
  const PosedObject posed = pose_canonical(object, 0.0);
  // One joint 1 cm off a vertex (along +x: no other vertex nearer for a convex part's
  // outermost vertex), another 20 cm away; the rest of the 32 at 1 m.
  Eigen::Index far_x = 0;
  posed.bottom.col(0).maxCoeff(&far_x);
  const Eigen::Vector3d v = posed.bottom.row(far_x).transpose();
  at::Tensor x = at::ones({1, 2, 96});
  for (int c = 0; c < 3; ++c) {
    x[0][1][c] = v[c] + (c == 0 ? 0.01 : 0.0);
    x[0][1][3 + c] = v[c] + (c == 0 ? 0.2 : 0.0);
  }
  const at::Tensor before = x.clone();
  const at::Tensor y = contact.impose(x, 1, 10, 50);
  EXPECT_TRUE(at::equal(x, before));  // the input is left as it is
  const at::Tensor on = y[0][1].slice(0, 0, 3).to(at::kDouble);
  const Eigen::Vector3d moved(on[0].item<double>(), on[1].item<double>(), on[2].item<double>());
  EXPECT_LT((moved - v).norm(), 0.0101);  // on a vertex, at most the 1 cm away
  EXPECT_NEAR(moved.x(), v.x(), 0.0101);
  EXPECT_TRUE(at::equal(y[0][1].slice(0, 3, 6), x[0][1].slice(0, 3, 6)));  // 20 cm: left alone
  EXPECT_TRUE(at::equal(y[0][0], x[0][0]));                                  // 1 m: left alone
  EXPECT_HAS(error_of([&] { contact.impose(x, 2, 10, 50); }), "outside the 3 frames");
}

TEST(Baselines, CamsBStagesFollowWhatTheObjectDoesAndHoldTheirMiddleFramesTarget) {
  // Still 0-9, carried 10-29 (with a 3-frame pause at 18-20), opened 30-49, still 50-59.
  at::Tensor states = at::zeros({60, 7}, at::kDouble);
  for (int t = 1; t < 60; ++t) {
    states[t] = states[t - 1];
    if (t >= 11 && t <= 30 && !(t >= 19 && t <= 21)) states[t][4] += 0.01;
    if (t >= 31 && t <= 50) states[t][0] += 0.05;
  }
  const auto stages = manipulation_stages(states, 8);
  ASSERT_EQ(stages.size(), 4u);
  const std::vector<std::array<std::int64_t, 3>> want{{0, 9, 0}, {10, 29, 1}, {30, 49, 2}, {50, 59, 0}};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(stages[k].first, want[k][0]) << k;
    EXPECT_EQ(stages[k].last, want[k][1]) << k;
    EXPECT_EQ(stages[k].what, want[k][2]) << k;
  }
  EXPECT_EQ(stages_from_tensor(stages_tensor(stages)).back().last, 59);
  // Targets: each stage's frames hold its middle frame's map.
  const at::Tensor maps = at::arange(60, at::kFloat).view({60, 1, 1}).expand({60, 2, 4}).contiguous();
  const at::Tensor t = stage_contact_targets(maps, stages);
  EXPECT_EQ(t[0][0][0].item<float>(), 4.0f);
  EXPECT_EQ(t[29][1][3].item<float>(), 19.0f);
  EXPECT_EQ(t[30][0][0].item<float>(), 39.0f);
  EXPECT_EQ(t[59][0][0].item<float>(), 54.0f);
}

TEST(Baselines, CamsBPlacesHandsThroughItsPipelineToSequencesBimartEvalReads) {
  const fs::path out = scratch("cams_b_run");
  const test::CliRun r = test::run_bimart(
      "generate " + testing_data::tiny_dataset().dir.string() + " --samples 2 --window 32 --out " + out.string() +
      " --pipeline " + kSource + "/pipelines/generate_eval_cams_b.yaml --set contact.sampler=ddim --set contact.steps=3" +
      " --set refine.rounds=1 --set refine.max_rounds=1 --set refine.steps=5");
  ASSERT_EQ(exit_code(r), 0) << r.output;
  EXPECT_HAS(r.output, "motion.cams_b: 1 stages");  // the tiny trajectory is one stage
  for (const char* folder : {"guided", "refined"}) {
    const fs::path f = out / folder / "test_d_f024_s01.npz";
    ASSERT_TRUE(fs::exists(f)) << f;
    const Sequence s = read_sequence(f.string());
    EXPECT_EQ(s.num_frames(), 32);
    EXPECT_TRUE(at::isfinite(s.hands.hands[1].trans).all().item<bool>());
  }
  const test::CliRun e = bimart_in_source("eval " + (out / "refined").string());
  ASSERT_EQ(exit_code(e), 0) << e.output;
  EXPECT_HAS(e.output, "2 sequences, 1 trajectories");
  EXPECT_HAS(bimart_in_source("plugins").output, "contact.cams_b");
}

}  // namespace
}  // namespace bimart::diffusion
