// refine.mano_fit and refine.ceres as pipeline stages, through the CLI: one synthetic
// sequence, corrupted keypoints (motion.ground_truth, with contact.ground_truth's maps
// written beside them), and two pipelines that differ by the
// `refine` stage alone — the ablation rows "w C + CG" and "w C + CG + Opt". The refined
// hands must be smoother and no deeper than the fitted ones; `bimart refine` on the same
// folder must print its table.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include <ATen/ATen.h>
#include <nlohmann/json.hpp>

#include "core/features/contact_map.h"
#include "core/io/sequence.h"
#include "core/metrics/accel.h"
#include "core/metrics/frame_depths.h"
#include "core/metrics/hand_vertices.h"
#include "core/object/object_io.h"
#include "tests/cli/run_bimart.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

test::CliRun run_cli(const std::string& args) { return test::run_bimart(args); }

std::string pipeline(const fs::path& sequence, const fs::path& out, bool refine) {
  std::string y = "name: t\nseed: 0\nstages:\n"
                  "  - id: sequence\n    use: trajectory.sequence\n    params: {path: \"" + sequence.string() + "\"}\n"
                  "  - id: encoder\n    use: encoder.np_bps\n"
                  "  - id: contact\n    use: contact.ground_truth\n"  // written with the sequence
                  "  - id: motion\n    use: motion.ground_truth\n    params: {seed: 3}\n"
                  "  - id: fit\n    use: refine.mano_fit\n";
  if (refine) y += "  - id: refine\n    use: refine.ceres\n";  // the one line between the rows
  y += "  - id: write\n    use: export.sequence\n    params: {path: \"" + out.string() + "\"}\n";
  return y;
}

TEST(RefinePipeline, TheRefineStageMakesTheFitSmootherAndNoDeeper) {
  const fs::path dir = fs::temp_directory_path() / ("bimart_refine_pipeline_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  auto [status, out] = run_cli("data synth --out " + (dir / "data").string() +
                               " --categories box --train-objects 1 --test-objects 0 --sequences 2 "
                               "--min-frames 120 --max-frames 120 --quiet");
  ASSERT_EQ(status, 0) << out;
  fs::path sequence;
  for (const auto& e : fs::recursive_directory_iterator(dir / "data" / "sequences"))
    if (e.path().extension() == ".npz" && (sequence.empty() || e.path() < sequence)) sequence = e.path();
  ASSERT_FALSE(sequence.empty()) << out;

  std::array<Sequence, 2> results;
  for (int refine = 0; refine < 2; ++refine) {
    const fs::path yaml = dir / (refine ? "refine.yaml" : "fit.yaml");
    const fs::path result = dir / (refine ? "refined.npz" : "fitted.npz");
    std::ofstream(yaml) << pipeline(sequence, result, refine);
    auto [s, o] = run_cli("run " + yaml.string());
    ASSERT_EQ(s, 0) << o;
    if (refine) EXPECT_NE(o.find("refine.ceres: 120 frames"), std::string::npos) << o;
    results[refine] = read_sequence(result.string());
  }
  const Sequence truth = read_sequence(sequence.string());
  const ArticulatedObject object = load_object(resolve_object_path(truth, sequence.string()));
  // contact.ground_truth wrote the truth's contact maps on the encoder's rows; the synthetic
  // hands touch the object somewhere in the sequence.
  const at::Tensor C = results[0].contact_maps;
  ASSERT_TRUE(C.defined() && results[0].basis_hit_indices.defined());
  const at::Tensor expected =
      world_contact_maps(object, truth.object_states, results[0].basis_hit_indices, hand_vertices(truth.hands));
  EXPECT_LT((C - expected.to(at::kFloat)).abs().max().item<float>(), 1e-6);
  EXPECT_LT(C.min().item<float>(), 0.005);
  const ObjectDistance distance(object);
  auto deepest = [&](const Sequence& s) {
    const FrameDepths d = frame_depths(distance, s.object_states, hand_vertices(s.hands));
    double m = -1;
    for (size_t t = 0; t < d.size(); ++t) m = std::max(m, d.whole(t));
    return m;
  };
  const double accel_fit = mean_acceleration(hand_vertices(results[0].hands));
  const double accel_refined = mean_acceleration(hand_vertices(results[1].hands));
  EXPECT_LT(accel_refined, 0.5 * accel_fit);
  EXPECT_LT(accel_refined, 2 * mean_acceleration(hand_vertices(truth.hands)));
  EXPECT_LE(deepest(results[1]), std::max(deepest(results[0]), 0.005));
  // The written files are sequences `bimart eval` reads (their object paths resolve).
  auto [es, eo] = run_cli("eval " + dir.string() + " --quiet");
  EXPECT_EQ(es, 0) << eo;
  EXPECT_NE(eo.find("generated (4)"), std::string::npos) << eo;

  // The command behind docs/results.md on the same folder, with the bars.
  auto [rs, ro] = run_cli("refine " + (dir / "data").string() + " --limit 1 --out " + (dir / "cli").string() +
                          " --json " + (dir / "refine.json").string() + " --quiet");
  ASSERT_EQ(rs, 0) << ro;
  EXPECT_NE(ro.find("fit + refine (+ Opt)"), std::string::npos) << ro;
  EXPECT_TRUE(fs::exists(dir / "cli" / "refined" / sequence.filename())) << ro;
  nlohmann::json j;
  std::ifstream(dir / "refine.json") >> j;
  const auto& rows = j["rows"];
  const auto& gt = rows["ground truth"];
  const auto& input = rows["input keypoints"];
  const auto& refined = rows["fit + refine (+ Opt)"];
  EXPECT_LE(refined["Pen 1cm"].get<double>(), gt["Pen 1cm"].get<double>() + 1.0) << ro;
  EXPECT_LT(refined["Accel"].get<double>(), input["Accel"].get<double>()) << ro;
  EXPECT_GE(refined["Con"].get<double>(), 95.0) << ro;
  EXPECT_LT(j["joint_error_mm"]["refined"].get<double>(), 10.0) << ro;

  // Each round's step checked against the exact surface (backtrack, off by default): the
  // steps that carried this sequence's fingers 5-10 mm into the box are cut back
  // (docs/refinement.md). Bounded joint angles (off by default) keep out of it too.
  std::map<std::string, nlohmann::json> other;
  for (const std::string& flags : {std::string("--backtrack true"), std::string("--joint-angles true --backtrack true")}) {
    const fs::path json = dir / "other.json";
    auto [s, o] = run_cli("refine " + (dir / "data").string() + " --limit 1 --no-write " + flags + " --json " +
                          json.string() + " --quiet");
    ASSERT_EQ(s, 0) << o;
    nlohmann::json a;
    std::ifstream(json) >> a;
    other[flags] = a["rows"]["fit + refine (+ Opt)"];
  }
  const nlohmann::json& checked = other["--backtrack true"];
  EXPECT_LE(checked["Pen 5mm"].get<double>(), gt["Pen 5mm"].get<double>() + 2.5) << ro;  // 3 of 120 frames
  EXPECT_GT(refined["Pen 5mm"].get<double>(), checked["Pen 5mm"].get<double>() + 2.0) << ro;
  EXPECT_LE(other["--joint-angles true --backtrack true"]["Pen 1cm"].get<double>(), gt["Pen 1cm"].get<double>() + 1.0);
  fs::remove_all(dir);
}

TEST(RefinePipeline, RefuseAnUnknownKeypointSource) {
  auto [s, o] = run_cli("refine . --keypoints predicted");
  EXPECT_NE(s, 0);
  EXPECT_NE(o.find("--keypoints"), std::string::npos) << o;
}

}  // namespace
}  // namespace bimart
