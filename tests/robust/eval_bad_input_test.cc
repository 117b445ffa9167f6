// `bimart eval` on spoiled sequence files: each refused with exit code 1 and a message
// naming the file, the frame and the field; --keep-going evaluates the rest.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <cstring>

#include "core/hand/hand_model.h"
#include "core/io/npz.h"
#include "core/util/data_path.h"
#include "tests/cli/run_bimart.h"
#include "tests/robust/fixture.h"

namespace bimart {
namespace {

using test::run_bimart;
using test::ScratchDir;
namespace fs = std::filesystem;

int exit_code(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status); }

// A valid sequence written, then one array changed behind the writer's back (the writer
// refuses such values), as a buggy generator or a hand edit would leave it.
std::string spoiled(const ScratchDir& dir, const std::string& name, const std::string& key, int64_t index,
                    float value) {
  const std::string path = dir / ("gen/" + name + ".npz");
  write_sequence(test::hover_sequence(name), path);
  NpzFile npz = NpzFile::read(path);
  NpyArray a = npz.get(key);
  std::memcpy(a.data.data() + 4 * index, &value, 4);
  npz.set(key, a);
  npz.write(path);
  return path;
}

TEST(EvalBadInput, HugeRotationIsAnErrorNamingFileFrameAndFieldNotSigfpe) {
  ScratchDir dir("eval_rot");
  test::write_box(dir);
  const std::string file = spoiled(dir, "huge_rot", "left_rot", 0, 1e30f);  // left_rot[0] = [1e30, 0, 0]
  const auto r = run_bimart("eval " + (dir / "gen") + " --threads 1");
  EXPECT_EQ(exit_code(r.status), 1) << r.output;  // was 136 (SIGFPE in GMP), no message
  EXPECT_NE(r.output.find(file), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("'left_rot'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frame 0"), std::string::npos) << r.output;
}

TEST(EvalBadInput, HugePoseIsAnError) {
  ScratchDir dir("eval_pose");
  test::write_box(dir);
  const std::string file = spoiled(dir, "huge_pose", "right_pose", 45 * 3 + 7, 1e20f);  // frame 3
  const auto r = run_bimart("eval " + (dir / "gen") + " --threads 1");
  EXPECT_EQ(exit_code(r.status), 1) << r.output;
  EXPECT_NE(r.output.find(file), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("'right_pose', frame 3 [7]: value 1e+20 is beyond the bound"), std::string::npos)
      << r.output;
}

TEST(EvalBadInput, HandVerticesMustHaveTheModelsCount) {
  ScratchDir dir("eval_vertices");
  test::write_box(dir);
  Sequence s = test::hover_sequence("five");
  s.hands.vertices = at::zeros({2, 8, 5, 3});
  write_sequence(s, dir / "gen/five.npz");
  const auto r = run_bimart("eval " + (dir / "gen") + " --threads 1");
  EXPECT_EQ(exit_code(r.status), 1) << r.output;  // was accepted: metrics of 5 points
  EXPECT_NE(r.output.find("'hand_vertices' has 5 vertices per hand"), std::string::npos) << r.output;
}

TEST(EvalBadInput, HandModelWithoutOneHundredKeypointsIsRefusedAsByRefine) {
  ScratchDir dir("eval_keypoints");
  test::write_box(dir);
  write_sequence(test::hover_sequence("a"), dir / "gen/a.npz");
  // The shipped models with 50 keypoints: refine refused them, eval used them.
  for (const char* side : {"left", "right"}) {
    HandModel m = load_hand_model(find_data_file(std::string("models/hand/mano_") + side + ".npz"));
    m.keypoints.resize(50);
    save_hand_model(m, dir / (std::string("mano_") + side + ".npz"));
  }
  const std::string models = " --mano-left " + (dir / "mano_left.npz") + " --mano-right " + (dir / "mano_right.npz");
  const auto e = run_bimart("eval " + (dir / "gen") + " --threads 1" + models);
  EXPECT_EQ(exit_code(e.status), 1) << e.output;
  EXPECT_NE(e.output.find("has 50 keypoints"), std::string::npos) << e.output;
  EXPECT_NE(e.output.find("mano_left.npz"), std::string::npos) << e.output;
  const auto f = run_bimart("refine " + (dir / "gen") + " --no-write --threads 1" + models);
  EXPECT_EQ(exit_code(f.status), 1) << f.output;
  EXPECT_NE(f.output.find("has 50 keypoints"), std::string::npos) << f.output;
}

TEST(EvalBadInput, HandModelWithAHugeFiniteValueIsRefusedByName) {
  ScratchDir dir("eval_model_bounds");
  test::write_box(dir);
  write_sequence(test::hover_sequence("a"), dir / "gen/a.npz");
  // A finite 1e30 in the model's own template: it loaded, and every posed vertex became inf.
  const std::string right = find_data_file("models/hand/mano_right.npz");
  NpzFile npz = NpzFile::read(find_data_file("models/hand/mano_left.npz"));
  NpyArray a = npz.get("v_template");
  ASSERT_EQ(a.item_size(), 8);  // float64
  const double huge = 1e30;
  std::memcpy(a.data.data() + 8 * (3 * 5 + 1), &huge, 8);  // vertex 5, y
  npz.set("v_template", a);
  const std::string left = dir / "mano_left.npz";
  npz.write(left);
  try {
    load_hand_model(left);
    ADD_FAILURE() << "a template vertex at 1e30 m was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("v_template has the value 1e+30 at [5, 1], beyond the bound"),
              std::string::npos) << e.what();
  }
  const auto r = run_bimart("eval " + (dir / "gen") + " --threads 1 --mano-left " + left + " --mano-right " + right);
  EXPECT_EQ(exit_code(r.status), 1) << r.output;
  EXPECT_NE(r.output.find("mano_left.npz"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("beyond the bound"), std::string::npos) << r.output;
}

TEST(EvalBadInput, MissingObjectNamesTheSequence) {
  ScratchDir dir("eval_object");
  Sequence s = test::hover_sequence("lost");
  s.object = "../objects/gone";
  write_sequence(s, dir / "gen/lost.npz");
  const auto r = run_bimart("eval " + (dir / "gen") + " --threads 1");
  EXPECT_EQ(exit_code(r.status), 1) << r.output;
  EXPECT_NE(r.output.find((dir / "gen/lost.npz") + ": its object '../objects/gone'"), std::string::npos) << r.output;
}

TEST(EvalBadInput, KeepGoingListsBadFilesAndWritesTheJsonForTheRest) {
  ScratchDir dir("eval_keep_going");
  test::write_box(dir);
  write_sequence(test::hover_sequence("good1"), dir / "gen/good1.npz");
  write_sequence(test::hover_sequence("good2"), dir / "gen/good2.npz");
  const std::string bad = spoiled(dir, "bad", "left_trans", 3 + 1, 1e9f);
  test::write_text(dir / "gen/garbage.npz", "not a zip file");
  const std::string json = dir / "out/eval.json";
  const auto stop = run_bimart("eval " + (dir / "gen") + " --threads 2 --json " + json);
  EXPECT_EQ(exit_code(stop.status), 1) << stop.output;
  EXPECT_FALSE(fs::exists(json));
  const auto r = run_bimart("eval " + (dir / "gen") + " --threads 2 --keep-going --json " + json);
  EXPECT_EQ(exit_code(r.status), 1) << r.output;  // some input was bad
  EXPECT_NE(r.output.find("2 files skipped"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("generated (2)"), std::string::npos) << r.output;
  nlohmann::json j;
  std::ifstream(json) >> j;
  EXPECT_EQ(j["generated"]["sequences"], 2);
  ASSERT_EQ(j["generated"]["skipped"].size(), 2u);
  EXPECT_EQ(j["generated"]["skipped"][0]["file"], bad);
  EXPECT_NE(j["generated"]["skipped"][0]["error"].get<std::string>().find("'left_trans', frame 1"), std::string::npos);
  EXPECT_EQ(j["generated"]["skipped"][1]["file"], dir / "gen/garbage.npz");
}

}  // namespace
}  // namespace bimart
