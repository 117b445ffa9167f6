// The paper's Table 3 "Rep" rows other than MANO-Rep, end to end on the tiny data set
// (tests/data/tiny_dataset.h): tiny contact and motion models trained with `bimart train`
// on U-BPS, NPA-BPS and NP-BPS without G, sampled through a pipeline whose encoder stage is
// that variant's (contact.diffusion, guidance.contact_map with placement and hold,
// motion.diffusion, refine.mano_fit, export.sequence), then `bimart eval` with every
// metric, CM included. A model given a pipeline of another variant, or contact maps of a
// model of another row, is refused before it samples, with a message naming both sides.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include <ATen/ATen.h>
#include <nlohmann/json.hpp>

#include "core/diffusion/checkpoint.h"
#include "core/diffusion/object_condition.h"
#include "core/io/sequence.h"
#include "tests/cli/run_bimart.h"
#include "tests/data/tiny_dataset.h"

namespace fs = std::filesystem;
using namespace bimart;

namespace {

#define EXPECT_HAS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "output: " << (haystack)

fs::path scratch() {
  static const fs::path dir = fs::temp_directory_path() / ("bimart_rep_variants_" + std::to_string(::getpid()));
  return dir;
}

// A Table 3 row: the encoder variant and whether the models read G.
struct Row {
  std::string name, variant;
  bool global_states = true;
};
const Row kUBps{"u_bps", "u_bps"}, kNpaBps{"npa_bps", "npa_bps"}, kNoG{"no_g", "np_bps", false},
    kNpBps{"np_bps", "np_bps"};

// The exported model of a row, trained once per process: a few steps of a tiny network.
std::string model(const Row& row, const std::string& kind) {
  static std::map<std::string, std::string> done;
  const std::string key = row.name + "_" + kind;
  if (done.count(key)) return done[key];
  const fs::path dir = scratch() / key;
  fs::create_directories(dir);
  const fs::path yaml = dir / "config.yaml";
  std::ofstream(yaml) << "model: " << kind << "\ndata: " << testing_data::tiny_dataset().dir.string()
                      << "\nout: " << dir.string() << "\nexport: " << (dir / "model.npz").string()
                      << "\nvariant: " << row.variant
                      << "\nnetwork:\n  latent: 16\n  layers: 1\n  heads: 2\n  feedforward: 32\n  condition_hidden: 16\n"
                      << "  global_states: " << (row.global_states ? "true" : "false")
                      << "\ntraining:\n  batch: 4\n  steps: 3\n  lr: 1.0e-3\n  warmup: 1\n  checkpoint_every: 3\n"
                      << "  validate_every: 0\n  log_every: 1\n  seed: 3\n";
  const test::CliRun r = test::run_bimart("-q train " + kind + " " + yaml.string());
  EXPECT_EQ(exit_code(r), 0) << r.output;
  return done[key] = (dir / "model.npz").string();
}

std::string test_sequence() { return (testing_data::tiny_dataset().dir / "sequences" / "test_d.npz").string(); }

// The generating pipeline of a row: `encoder` stage `use`, the two models, 2 samples (DDIM
// with 5 steps and a short MANO fit: the stages and files are the same, and the suite
// checks the plumbing, not the quality).
std::string pipeline(const std::string& encoder, const std::string& contact, const std::string& motion,
                     const fs::path& out) {
  return "name: rep\nseed: 1\nstages:\n"
         "  - id: sequence\n    use: trajectory.sequence\n    params: {path: \"" + test_sequence() + "\"}\n"
         "  - id: encoder\n    use: " + encoder + "\n"
         "  - id: contact\n    use: contact.diffusion\n    params: {checkpoint: \"" + contact + "\", samples: 2, sampler: ddim, steps: 5}\n"
         "  - id: guidance\n    use: guidance.contact_map\n"
         "    params: {place_steps: 1, place_snap: 0.03, hold: true, hold_place: true, release_steps: 2}\n"
         "  - id: motion\n    use: motion.diffusion\n    params: {checkpoint: \"" + motion + "\", samples: 2, sampler: ddim, steps: 5}\n"
         "  - id: fit\n    use: refine.mano_fit\n    params: {max_iterations: 5}\n"
         "  - id: write\n    use: export.sequence\n    params: {path: \"" + (out / "s{sample}.npz").string() + "\"}\n";
}

// Not quiet: the diffusion stages log a line once they have sampled.
test::CliRun run(const std::string& name, const std::string& yaml_text) {
  const fs::path yaml = scratch() / (name + ".yaml");
  fs::create_directories(scratch());
  std::ofstream(yaml) << yaml_text;
  return test::run_bimart("run " + yaml.string());
}

class RepVariants : public ::testing::Test {
 protected:
  static void TearDownTestSuite() { fs::remove_all(scratch()); }

  // Trains, samples, fits, exports and evaluates one row.
  static void end_to_end(const Row& row) {
    const std::string contact = model(row, "contact"), motion = model(row, "motion");
    const diffusion::Checkpoint ck = diffusion::load_checkpoint(motion);
    EXPECT_EQ(ck.info.variant, row.variant);
    EXPECT_EQ(diffusion::reads_global_states(ck.info.network), row.global_states);
    EXPECT_EQ(diffusion::reads_global_states(diffusion::load_checkpoint(contact).info.network), row.global_states);

    const fs::path out = scratch() / ("out_" + row.name);
    const test::CliRun r = run(row.name, pipeline("encoder." + row.variant, contact, motion, out));
    ASSERT_EQ(exit_code(r), 0) << r.output;
    for (const char* f : {"s0.npz", "s1.npz"}) {
      const Sequence s = read_sequence((out / f).string());
      ASSERT_TRUE(s.contact_maps.defined() && s.basis_hit_indices.defined()) << f;
      EXPECT_EQ(s.contact_maps.sizes(), (at::IntArrayRef{80, 2, 1024}));
      EXPECT_TRUE(at::isfinite(s.hands.hands[0].trans).all().item<bool>());
    }
    const fs::path json = scratch() / (row.name + "_metrics.json");
    const test::CliRun e = test::run_bimart("-q eval " + out.string() + " --json " + json.string());
    ASSERT_EQ(exit_code(e), 0) << e.output;
    std::ifstream in(json);
    const nlohmann::json j = nlohmann::json::parse(in);
    // Every metric of the table has a value, CM (the refit hands' keypoints against the
    // maps that conditioned them, on this variant's basis rows) included.
    std::map<std::string, double> values;
    const std::function<void(const nlohmann::json&)> collect = [&](const nlohmann::json& n) {
      if (n.is_object() && n.contains("name") && n.contains("value") && n.contains("higher_is_better"))
        values[n["name"].get<std::string>()] = n["value"].is_number() ? n["value"].get<double>() : NAN;
      if (n.is_structured())
        for (const auto& x : n) collect(x);
    };
    collect(j);
    for (const char* metric : {"Mul", "Accel", "Pen 1cm", "Pen 5mm", "Con", "Art", "CM"}) {
      ASSERT_TRUE(values.count(metric)) << metric << " missing: " << j.dump();
      EXPECT_TRUE(std::isfinite(values[metric]) && values[metric] >= 0) << metric << ": " << j.dump();
    }
  }
};

TEST_F(RepVariants, UBpsTrainsSamplesFitsAndEvaluates) { end_to_end(kUBps); }
TEST_F(RepVariants, NpaBpsTrainsSamplesFitsAndEvaluates) { end_to_end(kNpaBps); }
TEST_F(RepVariants, NpBpsWithoutGTrainsSamplesFitsAndEvaluates) { end_to_end(kNoG); }

TEST_F(RepVariants, AModelOfAnotherVariantIsRefusedBeforeSampling) {
  const std::string contact = model(kUBps, "contact"), motion = model(kUBps, "motion");
  for (const char* encoder : {"np_bps", "npa_bps"}) {
    SCOPED_TRACE(encoder);
    const fs::path out = scratch() / "refused";
    const test::CliRun r = run("refused", pipeline(std::string("encoder.") + encoder, contact, motion, out));
    EXPECT_EQ(exit_code(r), 1) << r.output;
    EXPECT_HAS(r.output, contact);                     // the model file
    EXPECT_HAS(r.output, "trained on u_bps");          // its variant
    EXPECT_HAS(r.output, "encoder stage 'encoder'");   // the pipeline's stage
    EXPECT_HAS(r.output, std::string("gives ") + encoder);  // and its variant
    EXPECT_EQ(r.output.find("contact.diffusion: "), std::string::npos) << "sampled before refusing: " << r.output;
    EXPECT_FALSE(fs::exists(out / "s0.npz"));
  }
}

TEST_F(RepVariants, AMotionModelOfAnotherRowThanItsContactMapsIsRefused) {
  // Contact maps of a model without G for a motion model with G (both NP-BPS).
  const std::string contact = model(kNoG, "contact"), motion = model(kNpBps, "motion");
  const fs::path out = scratch() / "mixed";
  const test::CliRun r = run("mixed", pipeline("encoder.np_bps", contact, motion, out));
  EXPECT_EQ(exit_code(r), 1) << r.output;
  EXPECT_HAS(r.output, motion + " (np_bps, with G)");
  EXPECT_HAS(r.output, contact + " (np_bps, without G)");
  EXPECT_EQ(r.output.find("motion.diffusion: "), std::string::npos) << "sampled before refusing: " << r.output;
  EXPECT_FALSE(fs::exists(out / "s0.npz"));
}

}  // namespace
