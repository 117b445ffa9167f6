// `bimart eval` end to end through the CLI binary on a tiny generated folder.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <vector>

#include <ATen/ATen.h>
#include <nlohmann/json.hpp>

#include "core/hand/hand_model.h"
#include "core/io/sequence.h"
#include "core/util/data_path.h"
#include "core/object/families/families.h"
#include "core/object/object_io.h"
#include "tests/cli/run_bimart.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

using test::CliRun;

CliRun run_cli(const std::string& args) { return test::run_bimart("eval " + args); }

// Hands hovering 2 cm above the closed box's lid at x = -0.05, moved by `offset` (m) in z.
// Stored hand_vertices must have the hand model's vertex count (the rule of every command).
int64_t model_vertices() {
  static const int64_t v = load_hand_model(find_data_file("models/hand/mano_left.npz")).num_vertices();
  return v;
}

Sequence sequence(const std::string& name, const at::Tensor& states, double offset) {
  const int64_t n = states.size(0), v = model_vertices();
  Sequence s;
  s.name = name;
  s.object = "../objects/box";
  s.category = "box";
  s.kind = "use";
  s.object_states = states;
  for (auto& h : s.hands.hands) {
    h.rot = at::zeros({n, 3});
    h.pose = at::zeros({n, 45});
    h.trans = at::zeros({n, 3});
    h.shape = at::zeros({10});
  }
  s.hands.vertices = at::zeros({2, n, v, 3});
  s.hands.vertices.select(3, 0).fill_(-0.05);
  s.hands.vertices.select(3, 1).fill_(0.5);  // far above
  s.hands.vertices.select(3, 2).fill_(offset);
  return s;
}

TEST(EvalCli, TableAndJsonOnATinyFolder) {
  const fs::path dir = fs::temp_directory_path() / ("bimart_eval_cli_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  save_object(make_object("box", 1), (dir / "objects" / "box").string());
  at::Tensor still = at::zeros({8, 7});
  at::Tensor moving = at::zeros({8, 7});
  moving.select(1, 4).copy_(at::arange(8, at::kFloat) * 0.01);
  moving.select(1, 0).copy_(at::arange(8, at::kFloat) * 0.05);
  // Two samples of one trajectory 3 cm apart, and one other trajectory.
  write_sequence(sequence("a_s0", moving, 0.0), (dir / "gen" / "a_s0.npz").string());
  write_sequence(sequence("a_s1", moving, 0.03), (dir / "gen" / "a_s1.npz").string());
  Sequence b = sequence("b", still, 0.0);
  b.object = "../../objects/box";  // relative to the file's own folder
  write_sequence(b, (dir / "gen" / "sub" / "b.npz").string());
  // A "data set" with a manifest: only the test split is read.
  write_sequence(sequence("gt0", moving, 0.0), (dir / "data" / "seq" / "gt0.npz").string());
  write_sequence(sequence("gt1", still, 0.0), (dir / "data" / "seq" / "gt1.npz").string());
  std::ofstream(dir / "data" / "manifest.json") << R"({"train": ["seq/gt1.npz"], "test": ["seq/gt0.npz"]})";
  // The data set's sequences refer to ../objects relative to data/seq.
  fs::create_directories(dir / "data" / "objects");
  fs::copy(dir / "objects" / "box", dir / "data" / "objects" / "box");

  const fs::path json = dir / "out" / "eval.json";
  const CliRun r = run_cli((dir / "gen").string() + " --ground-truth " + (dir / "data").string() +
                    " --split test --json " + json.string() + " --threads 2");
  // --split applies to both folders; the generated folder has no manifest.
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("manifest.json"), std::string::npos) << r.output;

  const CliRun ok = run_cli((dir / "gen").string() + " --json " + json.string() + " --threads 2");
  ASSERT_EQ(ok.status, 0) << ok.output;
  std::cout << ok.output;
  EXPECT_NE(ok.output.find("Mul"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find("Pen 1cm"), std::string::npos);
  nlohmann::json j;
  std::ifstream(json) >> j;
  const auto& g = j["generated"];
  EXPECT_EQ(g["sequences"], 3);
  EXPECT_EQ(g["trajectories"], 2);
  EXPECT_EQ(g["metrics"][0]["name"], "Mul");
  EXPECT_NEAR(g["metrics"][0]["value"].get<double>(), 3.0, 1e-4);  // cm
  EXPECT_EQ(g["metrics"][1]["name"], "Accel");
  EXPECT_NEAR(g["metrics"][1]["value"].get<double>(), 0.0, 1e-6);  // hands do not move
  EXPECT_EQ(g["metrics"][2]["name"], "Pen 1cm");
  EXPECT_EQ(g["metrics"][2]["denominator"], 24);  // all frames of all sequences
  EXPECT_EQ(g["metrics"][2]["numerator"], 0);
  EXPECT_EQ(g["metrics"][4]["name"], "Pen 3mm");
  EXPECT_EQ(g["metrics"][4]["numerator"], 0);
  EXPECT_EQ(g["metrics"][5]["name"], "Depth");
  EXPECT_TRUE(g["metrics"][5]["value"].is_null());  // no frame touches: no depth to average
  EXPECT_EQ(g["metrics"][6]["name"], "Con");
  EXPECT_EQ(g["metrics"][6]["denominator"], 14);  // 7 moving frames in each of a_s0, a_s1
  EXPECT_EQ(g["metrics"][6]["numerator"], 0);     // hands half a metre away
  EXPECT_EQ(g["metrics"][7]["name"], "Art");
  EXPECT_EQ(g["metrics"][7]["denominator"], 14);
  EXPECT_TRUE(g["metrics"][8]["value"].is_null());  // no conditioning maps stored: no CM
  EXPECT_EQ(g["per_sequence"].size(), 3u);

  const CliRun gt = run_cli("--ground-truth " + (dir / "data").string() + " --split test --quiet");
  ASSERT_EQ(gt.status, 0) << gt.output;
  EXPECT_NE(gt.output.find("ground truth (1)"), std::string::npos) << gt.output;

  // Own hand models: the shipped files given explicitly give the same table; a swapped
  // pair or a single file is refused.
  const std::string left = find_data_file("models/hand/mano_left.npz"), right = find_data_file("models/hand/mano_right.npz");
  const CliRun own = run_cli("--ground-truth " + (dir / "data").string() + " --split test --quiet --mano-left " +
                             left + " --mano-right " + right);
  ASSERT_EQ(own.status, 0) << own.output;
  EXPECT_EQ(own.output, gt.output);
  const CliRun swapped = run_cli("--ground-truth " + (dir / "data").string() + " --split test --quiet --mano-left " +
                                 right + " --mano-right " + left);
  EXPECT_NE(swapped.status, 0);
  EXPECT_NE(swapped.output.find("expected a left"), std::string::npos) << swapped.output;
  const CliRun one = run_cli("--ground-truth " + (dir / "data").string() + " --quiet --mano-left " + left);
  EXPECT_NE(one.status, 0);
  EXPECT_NE(one.output.find("both hand models"), std::string::npos) << one.output;

  const CliRun empty = run_cli((dir / "objects").string());
  EXPECT_NE(empty.status, 0);
  EXPECT_NE(empty.output.find("no .npz"), std::string::npos) << empty.output;
  fs::remove_all(dir);
}

// --frames: one row per frame and hand, and the rows say what the table counts — the frames
// with a row deeper than 5 mm are Pen 5mm's. The right hand sinks 3 cm per frame through
// the box (all its vertices at one point), the left stays half a metre away.
TEST(EvalCli, FramesCsvHasARowPerFrameAndHandThatAgreesWithPen) {
  const fs::path dir = fs::temp_directory_path() / ("bimart_eval_frames_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  save_object(make_object("box", 1), (dir / "objects" / "box").string());
  const int64_t n = 8;
  Sequence s = sequence("sink", at::zeros({n, 7}), 0.0);
  for (int64_t t = 0; t < n; ++t) s.hands.vertices[1][t].select(1, 1).fill_(0.2 - 0.03 * static_cast<double>(t));
  write_sequence(s, (dir / "gen" / "sink.npz").string());
  const fs::path csv = dir / "frames.csv", json = dir / "eval.json";
  const CliRun r = run_cli((dir / "gen").string() + " --frames " + csv.string() + " --json " + json.string() + " --quiet");
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "set,sequence,frame,hand,depth_mm,vertex,region,part,through,cavity_mm,closest_fingers_mm,implausible");
  int rows = 0, deep_frames = 0, inside = 0;
  while (std::getline(in, line)) {
    ++rows;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) f.push_back(c);
    ASSERT_GE(f.size(), 11u) << line;
    EXPECT_EQ(f[0], "generated");
    EXPECT_EQ(f[1], "sink.npz");
    const double depth = std::stod(f[4]);
    if (f[3] == "left") EXPECT_LT(depth, -100.0) << line;  // half a metre off
    if (depth > 0) {
      ++inside;
      EXPECT_EQ(f[3], "right");
      EXPECT_EQ(f[5], "0") << line;  // all vertices at one point: the first is the deepest
      EXPECT_FALSE(f[6].empty());
    }
    if (f[3] == "right" && depth > 5.0) ++deep_frames;
  }
  EXPECT_EQ(rows, 2 * n);
  EXPECT_GT(inside, 0);
  nlohmann::json j;
  std::ifstream(json) >> j;
  EXPECT_EQ(j["generated"]["metrics"][3]["name"], "Pen 5mm");
  EXPECT_EQ(j["generated"]["metrics"][3]["numerator"].get<int>(), deep_frames);
  EXPECT_GT(deep_frames, 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace bimart
