// The "w/o G" ablation (paper Table 3, `network.global_states: false`): the config switch
// sets the object condition's width, the checkpoint keeps it (older files read as with
// G), and a model trained without G never sees G — changing G changes a with-G model's
// samples and leaves a without-G model's bit for bit the same.
#include <gtest/gtest.h>

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/data/normalization.h"
#include "core/data/window_dataset.h"
#include "core/diffusion/checkpoint.h"
#include "core/diffusion/generation.h"
#include "core/diffusion/object_condition.h"
#include "core/diffusion/training.h"
#include "core/io/npz.h"
#include "core/util/error.h"
#include "tests/data/tiny_dataset.h"
#include "tests/diffusion/tiny_train_config.h"
#include "tests/error_of.h"

using bimart::test::error_of;

namespace bimart::diffusion {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("bimart_global_states_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TrainConfig tiny(const fs::path& out, const std::string& model, bool global_states) {
  TrainConfig c = tiny_train_config(out, model);
  c.global_states = global_states;
  c.network.object_condition_size = object_condition_size(global_states);
  c.steps = 3;
  c.lr = 1e-2;
  c.warmup = 1;
  c.validate_every = 0;
  c.seed = 7;
  return c;
}

Checkpoint trained(const std::string& name, const std::string& model, bool global_states) {
  const fs::path dir = scratch(name);
  TrainOptions quiet;
  quiet.progress = false;
  EXPECT_TRUE(train(tiny(dir, model, global_states), quiet).finished);
  return load_checkpoint((dir / "checkpoint.npz").string());
}

TEST(GlobalStates, ConfigSwitchSetsTheObjectConditionWidth) {
  const fs::path dir = scratch("config");
  const fs::path yaml = dir / "c.yaml";
  std::ofstream(yaml) << "model: contact\ndata: d\nout: o\n";
  EXPECT_TRUE(load_train_config(yaml.string()).global_states);
  EXPECT_EQ(load_train_config(yaml.string()).network.object_condition_size, 3079);
  std::ofstream(yaml) << "model: motion\ndata: d\nout: o\nnetwork:\n  global_states: false\n";
  const TrainConfig c = load_train_config(yaml.string());
  EXPECT_FALSE(c.global_states);
  EXPECT_EQ(c.network.object_condition_size, 3072);
  EXPECT_FALSE(reads_global_states(c.network));
  // The contact cue reads s_o from G: not without G.
  std::ofstream(yaml) << "model: motion\ndata: d\nout: o\nnetwork:\n  global_states: false\n  contact_cue: true\n";
  EXPECT_THROW(load_train_config(yaml.string()), Error);
  // Switch and width must agree.
  TrainConfig odd = c;
  odd.global_states = true;
  EXPECT_NE(error_of([&] { validate(odd); }).find("global_states"), std::string::npos);
}

TEST(GlobalStates, TrainingFeedsAModelWithoutGOnlyO) {
  const TrainConfig c = tiny("/unused", "motion", false);
  const WindowDataset& data = testing_data::tiny_train();
  const NormalizationStats stats = compute_normalization(data);
  const StepInputs in = draw_step(c, stats, data, 0, 0);
  ASSERT_EQ(in.object.size(-1), 3072);
  // ... and those are O's normalised columns, the first 3072 of [O | G].
  TrainConfig with = c;
  with.global_states = true;
  with.network.object_condition_size = 3079;
  const StepInputs full = draw_step(with, stats, data, 0, 0);
  ASSERT_EQ(full.object.size(-1), 3079);
  EXPECT_TRUE(at::equal(in.object, full.object.narrow(-1, 0, 3072)));
}

TEST(GlobalStates, ChangingGChangesOnlyTheModelThatReadsIt) {
  for (const std::string model : {"contact", "motion"}) {
    SCOPED_TRACE(model);
    const Checkpoint without = trained(model + "_without", model, false);
    const Checkpoint with = trained(model + "_with", model, true);
    EXPECT_EQ(without.info.network.object_condition_size, 3072);
    EXPECT_EQ(without.weights.at("object_mlp.0.weight").size(1), 3072);
    EXPECT_EQ(with.weights.at("object_mlp.0.weight").size(1), 3079);

    const WindowBatch b = testing_data::tiny_train().batch({0});
    const at::Tensor O = b.object_features[0], G = b.global_states[0];
    at::Tensor moved = G.clone();
    moved.slice(1, 0, 3) += 0.7;  // another root rotation,
    moved.slice(1, 3, 6) += at::linspace(0, 0.5, G.size(0)).unsqueeze(1);  // path
    moved.select(1, 6) *= 1.5;    // and scale
    GenerateOptions o;
    o.sampler.sampler = "ddim";
    o.sampler.steps = 4;
    const auto sample = [&](const Checkpoint& ck, const at::Tensor& g) {
      const DiffusionModel m(ck, model + ".npz");
      const at::Tensor C = model == "motion" ? b.contact_maps[0] : at::Tensor();
      return m.generate(O, g, C, nullptr, o, at::detail::createCPUGenerator(5));
    };
    EXPECT_TRUE(at::equal(sample(without, G), sample(without, moved)));
    EXPECT_GT((sample(with, G) - sample(with, moved)).abs().max().item<double>(), 1e-5);
  }
}

TEST(GlobalStates, CheckpointKeepsTheSwitchAndOlderFilesReadG) {
  const Checkpoint without = trained("ckpt", "contact", false);
  const std::string path = (scratch("ckpt_files") / "without.npz").string();
  save_checkpoint(without, path);
  const NpzFile f = NpzFile::read(path);
  EXPECT_EQ(f.vector<std::int64_t>("network/global_states").at(0), 0);
  EXPECT_FALSE(reads_global_states(load_checkpoint(path).info.network));

  // A file from before the switch: no network/global_states, an object condition of 3079.
  Checkpoint with = without;
  with.info.network.object_condition_size = 3079;
  save_checkpoint(with, path);
  NpzFile older;
  for (const auto& key : NpzFile::read(path).keys())
    if (key != "network/global_states") older.set(key, NpzFile::read(path).get(key));
  older.write(path, NpzCompression::Store);
  EXPECT_TRUE(reads_global_states(load_checkpoint(path).info.network));
  // A flag that contradicts the width is refused, naming the file.
  older.set("network/global_states", make_npy_scalar<std::int64_t>(0));
  older.write(path, NpzCompression::Store);
  const std::string e = error_of([&] { load_checkpoint(path); });
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("global_states"), std::string::npos) << e;
}

TEST(GlobalStates, ResumeWithTheOtherSwitchIsRefused) {
  const fs::path dir = scratch("resume");
  TrainOptions quiet;
  quiet.progress = false;
  quiet.stop_after = 1;
  train(tiny(dir, "contact", false), quiet);
  TrainOptions resume;
  resume.progress = false;
  resume.resume = true;
  const std::string e = error_of([&] { train(tiny(dir, "contact", true), resume); });
  EXPECT_NE(e.find("global_states"), std::string::npos) << e;
}

}  // namespace
}  // namespace bimart::diffusion
