// MANO-Rep end to end on the tiny data set: the training-config switch, the data set's MANO
// representation (and its feature cache), the normalisation statistics, a tiny model that
// trains, saves, loads and samples through pipelines/generate_eval_mano_rep.yaml to sequence
// files `bimart eval` reads, and the refusals of a model given to the other stage.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <ATen/ATen.h>

#include "core/data/normalization.h"
#include "core/diffusion/checkpoint.h"
#include "core/diffusion/generation.h"
#include "core/diffusion/representation.h"
#include "core/diffusion/training.h"
#include "core/features/mano_representation.h"
#include "core/hand/hand_model.h"
#include "core/io/npz.h"
#include "core/io/sequence.h"
#include "core/metrics/hand_vertices.h"
#include "core/util/error.h"
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
  const fs::path dir = fs::temp_directory_path() / ("bimart_mano_rep_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The CLI in the source tree (the pipelines name models/ and pipelines/ relative to it).
test::CliRun bimart_in_source(const std::string& args) { return test::run_bimart("-q " + args); }

TrainConfig tiny_mano_config(const fs::path& out) {
  TrainConfig c = tiny_train_config(out, "motion");
  c.representation = kManoRepresentation;
  c.export_path = (out / "model.npz").string();
  c.network.sample_size = kManoRepSize;
  c.steps = 3;
  c.lr = 1e-3;
  c.warmup = 1;
  c.validate_every = 3;
  c.validation_windows = 2;
  c.log_every = 1;
  c.seed = 3;
  return c;
}

// One tiny MANO-Rep model for the tests below (a few seconds).
const fs::path& tiny_model() {
  static const fs::path model = [] {
    const fs::path dir = scratch("model");
    TrainOptions quiet;
    quiet.progress = false;
    const TrainResult r = train(tiny_mano_config(dir), quiet);
    EXPECT_TRUE(r.finished);
    EXPECT_TRUE(std::isfinite(r.last_loss));
    return dir / "model.npz";
  }();
  return model;
}

TEST(ManoRep, ConfigSwitchSetsTheSampleAndIsRefusedForTheContactModel) {
  const fs::path dir = scratch("config");
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const TrainConfig m = load_train_config(write("m.yaml", "model: motion\ndata: d\nout: o\nrepresentation: mano\n"));
  EXPECT_EQ(m.representation, "mano");
  EXPECT_EQ(m.network.sample_size, 294);
  const TrainConfig k = load_train_config(write("k.yaml", "model: motion\ndata: d\nout: o\n"));
  EXPECT_EQ(k.representation, "keypoints");
  EXPECT_EQ(k.network.sample_size, 1200);
  const std::string contact =
      error_of([&] { load_train_config(write("c.yaml", "model: contact\ndata: d\nout: o\nrepresentation: mano\n")); });
  EXPECT_HAS(contact, "c.yaml:4");
  EXPECT_HAS(contact, "motion model only");
  EXPECT_HAS(contact, "contact model");
  const std::string other =
      error_of([&] { load_train_config(write("x.yaml", "model: motion\ndata: d\nout: o\nrepresentation: fingers\n")); });
  EXPECT_HAS(other, "x.yaml:4");
  EXPECT_HAS(other, "keypoints, mano or joints");
  // In code: the sample size must agree with the representation.
  TrainConfig c = tiny_mano_config(dir / "run");
  c.network.sample_size = 1200;
  EXPECT_HAS(error_of([&] { validate(c); }), "294");
}

TEST(ManoRep, DataSetHoldsTheRepresentationOfItsHandsAndCachesItHonestly) {
  const fs::path cache = scratch("cache");
  WindowDatasetOptions o;
  o.cache_dir = cache.string();
  o.mano = true;
  o.half_precision = false;
  const std::string folder = testing_data::tiny_dataset().dir.string();
  const WindowDataset ds = WindowDataset::open(folder, "train", o);
  EXPECT_EQ(ds.load_report().computed, 3u);
  const WindowBatch b = ds.batch({0, static_cast<std::int64_t>(ds.size()) - 1});
  ASSERT_TRUE(b.mano.defined());
  ASSERT_EQ(b.mano.sizes(), (at::IntArrayRef{2, 64, kManoRepSize}));
  // Window 0 is frames 0..63 of the first train sequence, computed directly.
  const DatasetSequence& s = ds.sequences()[0];
  const Sequence seq = read_sequence(s.path);
  const std::array<HandModel, 2> models =
      load_hand_models(posing_hand_model_files()[0], posing_hand_model_files()[1]);
  // The data set's states: the object in its canonical pose (core/object/canonical_frame.h).
  const at::Tensor direct = mano_representation({&models[0], &models[1]}, seq.hands, s.states);
  EXPECT_LT((b.mano[0] - direct.slice(0, 0, 64)).abs().max().item<double>(), 1e-6);

  // Read back from the cache; a data set that does not ask for it reads the same files.
  const WindowDataset again = WindowDataset::open(folder, "train", o);
  EXPECT_EQ(again.load_report().cached, 3u);
  EXPECT_TRUE(at::equal(again.batch({0}).mano, b.mano.slice(0, 0, 1)));
  WindowDatasetOptions plain = o;
  plain.mano = false;
  const WindowDataset keypoints = WindowDataset::open(folder, "train", plain);
  EXPECT_EQ(keypoints.load_report().cached, 3u);
  EXPECT_FALSE(keypoints.batch({0}).mano.defined());
  // A cache written without it is stale for a data set that needs it.
  const fs::path cache2 = scratch("cache2");
  plain.cache_dir = o.cache_dir = cache2.string();
  EXPECT_EQ(WindowDataset::open(folder, "train", plain).load_report().computed, 3u);
  const WindowDataset recomputed = WindowDataset::open(folder, "train", o);
  EXPECT_EQ(recomputed.load_report().computed, 3u);
  EXPECT_TRUE(at::equal(recomputed.batch({0}).mano, b.mano.slice(0, 0, 1)));
}

TEST(ManoRep, NormalisationHoldsTheRepresentationsStatistics) {
  WindowDatasetOptions o;
  o.cache = false;
  o.mano = true;
  const WindowDataset ds = WindowDataset::open(testing_data::tiny_dataset().dir.string(), "train", o);
  const NormalizationStats st = compute_normalization(ds);
  ASSERT_TRUE(st.mano_mean.defined());
  EXPECT_EQ(st.mano_mean.sizes(), (at::IntArrayRef{kManoRepSize}));
  const WindowBatch b = ds.batch({0, 1, 2});
  const at::Tensor z = st.normalize_mano(b.mano);
  EXPECT_LT((st.denormalize_mano(z) - b.mano).abs().max().item<double>(), 1e-5);
  NpzFile f;
  store_normalization(st, f, "n/");
  const NormalizationStats back = read_normalization(f, "n/");
  EXPECT_TRUE(at::allclose(back.mano_std, st.mano_std));
  // Without the representation in the data set there are none, and none are stored.
  const NormalizationStats plain = compute_normalization(testing_data::tiny_train());
  EXPECT_FALSE(plain.mano_mean.defined());
  EXPECT_THROW(plain.normalize_mano(b.mano), Error);
}

TEST(ManoRep, CheckpointKnowsItsRepresentationAndOlderOnesLoadAsKeypoints) {
  const Checkpoint ck = load_checkpoint(tiny_model().string());
  EXPECT_EQ(ck.info.representation, "mano");
  EXPECT_EQ(ck.info.network.sample_size, kManoRepSize);
  EXPECT_TRUE(ck.info.normalization.mano_mean.defined());
  // A file from before the field: a keypoint model (here the shipped one, the key removed).
  const NpzFile shipped = NpzFile::read(kSource + "/models/motion.npz");
  NpzFile old;
  for (const auto& key : shipped.keys())
    if (key != "representation") old.set(key, shipped.get(key));
  const fs::path path = scratch("old") / "old.npz";
  old.write(path.string(), NpzCompression::Store);
  EXPECT_EQ(load_checkpoint(path.string()).info.representation, "keypoints");
  // A MANO-Rep model refuses to be resumed or started from as a keypoint model.
  const std::string msg = error_of([&] {
    check_compatible(ck.info, "m.npz", "motion", "", {}, {}, kKeypointsRepresentation);
  });
  EXPECT_HAS(msg, "mano (MANO-Rep)");
  EXPECT_HAS(msg, "keypoints (X = [H | D])");
}

TEST(ManoRep, TinyModelSamplesThroughThePipelineToSequencesBimartEvalReads) {
  const std::string model = tiny_model().string();
  const fs::path out = scratch("generate");
  const std::string few = " --set contact.sampler=ddim --set contact.steps=3 --set motion.sampler=ddim --set motion.steps=3";
  const test::CliRun r = bimart_in_source(
      "generate " + testing_data::tiny_dataset().dir.string() + " --samples 2 --window 32 --out " + out.string() +
      " --pipeline " + kSource + "/pipelines/generate_eval_mano_rep.yaml --set motion.checkpoint=" + model + few);
  ASSERT_EQ(exit_code(r), 0) << r.output;
  EXPECT_HAS(r.output, "1 windows x 2 samples");
  for (const char* k : {"s00", "s01"}) {
    const fs::path f = out / "guided" / (std::string("test_d_f024_") + k + ".npz");
    ASSERT_TRUE(fs::exists(f)) << f;
    const Sequence s = read_sequence(f.string());
    EXPECT_EQ(s.num_frames(), 32);
    EXPECT_TRUE(s.contact_maps.defined());  // for CM
    for (int h = 0; h < 2; ++h) EXPECT_TRUE(at::equal(s.hands.hands[h].shape, at::zeros({10})));  // β = 0
  }
  const test::CliRun e = bimart_in_source("eval " + (out / "guided").string() + " --json " + (out / "e.json").string());
  ASSERT_EQ(exit_code(e), 0) << e.output;
  EXPECT_HAS(e.output, "2 sequences, 1 trajectories");
  std::ifstream in(out / "e.json");
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_HAS(json, "\"CM\"");
}

TEST(ManoRep, StagesRefuseTheOtherRepresentationNamingBoth) {
  const std::string data = testing_data::tiny_dataset().dir.string();
  const fs::path out = scratch("refuse");
  // A MANO-Rep model in motion.diffusion.
  const test::CliRun a = bimart_in_source("generate " + data + " --window 32 --out " + (out / "a").string() +
                                          " --pipeline " + kSource + "/pipelines/generate_eval_fit.yaml" +
                                          " --set motion.checkpoint=" + tiny_model().string());
  EXPECT_EQ(exit_code(a), 1) << a.output;
  EXPECT_HAS(a.output, "motion.diffusion cannot sample");
  EXPECT_HAS(a.output, "it is a MANO-Rep motion model (sampling mano (MANO-Rep)");
  EXPECT_HAS(a.output, "sampled by motion.diffusion_mano");
  // A keypoint model in motion.diffusion_mano.
  const test::CliRun b = bimart_in_source("generate " + data + " --window 32 --out " + (out / "b").string() +
                                          " --pipeline " + kSource + "/pipelines/generate_eval_mano_rep.yaml" +
                                          " --set motion.checkpoint=" + kSource + "/models/motion.npz");
  EXPECT_EQ(exit_code(b), 1) << b.output;
  EXPECT_HAS(b.output, "motion.diffusion_mano cannot sample");
  EXPECT_HAS(b.output, "it is the method's motion model (sampling keypoints (X = [H | D])");
  EXPECT_HAS(b.output, "sampled by motion.diffusion;");
  // Guidance wired into motion.diffusion_mano.
  std::string yaml;
  {
    std::ifstream in(kSource + "/pipelines/generate_eval_mano_rep.yaml");
    yaml.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  const std::string motion = "  - id: motion\n";
  ASSERT_NE(yaml.find(motion), std::string::npos);
  yaml.insert(yaml.find(motion), "  - id: guidance\n    use: guidance.contact_map\n\n");
  std::ofstream(out / "guided.yaml") << yaml;
  const test::CliRun c = bimart_in_source(
      "generate " + data + " --window 32 --out " + (out / "c").string() + " --pipeline " + (out / "guided.yaml").string() +
      " --set motion.checkpoint=" + tiny_model().string() + " --set contact.sampler=ddim --set contact.steps=2");
  EXPECT_EQ(exit_code(c), 1) << c.output;
  EXPECT_HAS(c.output, "takes no guidance");
}

}  // namespace
}  // namespace bimart::diffusion
