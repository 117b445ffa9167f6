// The outputs in the tools people open them with (docs/outputs.md), one ctest entry each
// with its own label: the Khronos glTF validator (npm gltf-validator), Blender (Debian
// `blender`, headless) and Chromium (Debian `chromium`, headless, driven by puppeteer-core).
// A missing tool skips its test with a message, unless CI is set: then it fails.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/cli/sequence_files.h"
#include "core/hand/hand_model.h"
#include "core/io/sequence.h"
#include "core/object/object_io.h"
#include "tests/cli/run_bimart.h"
#include "tests/outputs/scene_fixture.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;

struct Shell {
  int status;
  std::string output;
};

Shell shell(const std::string& cmd) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  return {pclose(p), out};
}

bool have_program(const std::string& name) { return shell("command -v " + name).status == 0; }
bool have_npm_modules() { return fs::exists(fs::path(BIMART_TEST_NPM_DIR) / "node_modules" / "gltf-validator"); }

// Skips (or, with CI set, fails) the test when `present` is false.
#define REQUIRE_TOOL(present, what, how)                                                            \
  do {                                                                                              \
    if (!(present)) {                                                                               \
      if (std::getenv("CI")) FAIL() << what << " is missing, and CI is set: this test must run; " << how; \
      GTEST_SKIP() << what << " is not installed: test skipped (set CI=1 to make this a failure); " << how; \
    }                                                                                               \
  } while (0)

// Files every test here uses, made once per process in a scratch folder.
struct Inputs {
  // One folder per suite (each ctest entry runs one, maybe in parallel), replaced each run.
  fs::path dir = fs::path(BIMART_TEST_WORK_DIR) /
                 ("tools_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name()));
  std::vector<std::string> ground_truth;  // synthetic ground-truth sequences (shipped hands)
  fs::path corrective_seq = dir / "corrective" / "seq.npz";  // (members after `dir`)
  fs::path mano_left = dir / "corrective" / "mano_left.npz", mano_right = dir / "corrective" / "mano_right.npz";
  std::array<HandModel, 2> shipped = test::shipped_hand_models();
  std::array<HandModel, 2> corrective{test::with_correctives(shipped[0]), test::with_correctives(shipped[1])};

  Inputs() {
    fs::remove_all(dir);
    ground_truth = cli::sequence_files(BIMART_TEST_SYNTH_DIR, "");
    save_hand_model(corrective[0], mano_left.string());
    save_hand_model(corrective[1], mano_right.string());
    save_object(make_object("box", 3), (dir / "corrective" / "box").string());
    Sequence s = test::test_sequence(60, {&corrective[0], &corrective[1]});
    write_sequence(s, corrective_seq.string());
  }
  std::string corrective_hands() const { return " --mano-left " + mano_left.string() + " --mano-right " + mano_right.string(); }
};

const Inputs& inputs() {
  static const Inputs in;
  return in;
}

std::string export_glb(const std::string& seq, const fs::path& out, const std::string& extra = "") {
  const auto r = test::run_bimart("export " + seq + " --out " + out.string() + extra);
  EXPECT_EQ(r.status, 0) << r.output;
  std::printf("%s", r.output.c_str());
  return (out / (fs::path(seq).stem().string() + ".glb")).string();
}

TEST(Validator, GroundTruthAndCorrectiveScenesPass) {
  REQUIRE_TOOL(have_program("node") && have_npm_modules(), "node with gltf-validator (" BIMART_TEST_NPM_DIR ")",
               "run `ctest -R outputs.npm` with network once (tests/outputs/package-lock.json)");
  const Inputs& in = inputs();
  ASSERT_FALSE(in.ground_truth.empty());
  std::string files;
  for (const auto& seq : in.ground_truth) files += " " + export_glb(seq, in.dir / "validator");
  files += " " + export_glb(in.corrective_seq.string(), in.dir / "validator", in.corrective_hands());
  const Shell r = shell("NODE_PATH=" BIMART_TEST_NPM_DIR "/node_modules node " BIMART_TEST_SOURCE_DIR
                        "/validate_glb.js" + files);
  std::printf("%s", r.output.c_str());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find(": 0 errors, 0 warnings"), std::string::npos);
}

struct BlenderDump {
  nlohmann::json j;
  // The mesh object named `prefix` or `prefix` + suffix (Blender names a skinned mesh's
  // object after its mesh, "left_hand_mesh").
  std::string mesh(const std::string& prefix) const {
    for (const auto& [name, info] : j.at("meshes").items())
      if (name.rfind(prefix, 0) == 0) return name;
    throw Error("Blender imported no mesh " + prefix + ": " + j.at("meshes").dump());
  }
  Eigen::MatrixX3d vertices(int frame, const std::string& prefix) const {
    const auto& v = j.at("frames").at(std::to_string(frame)).at(mesh(prefix));
    Eigen::MatrixX3d out(v.size(), 3);
    for (size_t i = 0; i < v.size(); ++i) out.row(i) << v[i][0], v[i][1], v[i][2];
    return out;
  }
};

BlenderDump blender_dump(const std::string& glb, double fps, const std::vector<int>& frames) {
  std::string list;
  for (int f : frames) list += (list.empty() ? "" : ",") + std::to_string(f);
  const std::string out = glb + ".blender.json";
  const Shell r = shell("blender --background --factory-startup --python " BIMART_TEST_SOURCE_DIR "/blender_dump.py -- " +
                        glb + " " + std::to_string(fps) + " " + out + " " + list);
  EXPECT_EQ(r.status, 0) << r.output;
  std::ifstream f(out);
  if (!f) throw Error("blender wrote no " + out + ":\n" + r.output);
  BlenderDump d;
  f >> d.j;
  return d;
}

double max_error(const Eigen::MatrixX3d& a, const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>& b) {
  if (a.rows() != b.rows()) throw Error("vertex counts differ: " + std::to_string(a.rows()) + " vs " + std::to_string(b.rows()));
  return (a - Eigen::MatrixX3d(b)).rowwise().norm().maxCoeff();
}

struct Errors {
  double hands = 0, object = 0;
};

// Checks what Blender imported and returns the largest vertex errors at `frames`.
Errors check_in_blender(const std::string& glb, const Sequence& s, const ArticulatedObject& object,
                        const std::array<const HandModel*, 2>& models, const std::vector<int>& frames) {
  const BlenderDump d = blender_dump(glb, s.fps, frames);
  const auto& arm = d.j.at("armatures");
  EXPECT_EQ(arm.size(), 2u) << arm.dump();
  for (const auto& [name, bones] : arm.items()) EXPECT_EQ(bones.size(), 16u) << name;
  EXPECT_EQ(d.j.at("meshes").size(), 4u) << d.j.at("meshes").dump();
  for (const char* mesh : {"object_top", "object_bottom", "left_hand", "right_hand"}) EXPECT_NO_THROW(d.mesh(mesh));
  double last = 0;
  for (const auto& [name, range] : d.j.at("actions").items()) last = std::max(last, range[1].get<double>());
  EXPECT_NEAR(last, double(s.num_frames() - 1), 1e-3) << d.j.at("actions").dump();
  Errors e;
  const at::Tensor states = s.object_states.to(at::kDouble).contiguous();
  for (int t : frames) {
    for (int h = 0; h < 2; ++h)
      e.hands = std::max(e.hands, max_error(d.vertices(t, h == 0 ? "left_hand" : "right_hand"),
                                            test::posed_hand(s, *models[h], h, t).vertices));
    const PosedObject o = pose_world(object, ObjectState::from_row(states[t].data_ptr<double>()));
    e.object = std::max(e.object, max_error(d.vertices(t, "object_top"), o.top));
    e.object = std::max(e.object, max_error(d.vertices(t, "object_bottom"), o.bottom));
  }
  return e;
}

TEST(Blender, ImportsSkinnedHandsThatMatchBimart) {
  REQUIRE_TOOL(have_program("blender"), "blender", "scripts/setup.sh installs Debian's blender");
  const Inputs& in = inputs();
  const std::array<const HandModel*, 2> corrective{&in.corrective[0], &in.corrective[1]};
  const std::array<const HandModel*, 2> shipped{&in.shipped[0], &in.shipped[1]};
  const Sequence cs = read_sequence(in.corrective_seq.string());
  const ArticulatedObject box = load_object((in.corrective_seq.parent_path() / "box").string());
  const std::vector<int> frames{0, 30, 59};
  const Errors with = check_in_blender(export_glb(in.corrective_seq.string(), in.dir / "blender", in.corrective_hands()),
                                       cs, box, corrective, frames);
  const Errors without = check_in_blender(
      export_glb(in.corrective_seq.string(), in.dir / "blender_lbs", in.corrective_hands() + " --no-correctives"), cs, box,
      corrective, frames);
  std::printf("Blender vs bimart, frames 0, 30, 59, hands with 135 correctives each: hands %.4f mm with morph targets, "
              "%.4f mm without; object %.4f mm\n", 1e3 * with.hands, 1e3 * without.hands, 1e3 * with.object);
  EXPECT_LE(with.hands, 0.5e-3);
  EXPECT_LE(with.object, 0.1e-3);
  EXPECT_GT(without.hands, with.hands);

  // A synthetic ground-truth sequence with the shipped hands (no correctives).
  const std::string gt = in.ground_truth.front();
  const Sequence s = read_sequence(gt);
  const ArticulatedObject object = load_object(resolve_object_path(s, gt));
  const int n = static_cast<int>(s.num_frames());
  const Errors e = check_in_blender(export_glb(gt, in.dir / "blender_gt"), s, object, shipped, {0, n / 2, n - 1});
  std::printf("Blender vs bimart, %s (%d frames) at 0, %d, %d: hands %.4f mm, object %.4f mm\n", gt.c_str(), n, n / 2,
              n - 1, 1e3 * e.hands, 1e3 * e.object);
  EXPECT_LE(e.hands, 0.5e-3);
  EXPECT_LE(e.object, 0.1e-3);
}

TEST(Chromium, ViewerPlaysOfflineAndShowsHandsAndObject) {
  REQUIRE_TOOL(have_program("chromium"), "chromium", "scripts/setup.sh installs Debian's chromium");
  REQUIRE_TOOL(have_program("node") && have_npm_modules(), "node with puppeteer-core (" BIMART_TEST_NPM_DIR ")",
               "run `ctest -R outputs.npm` with network once");
  const Inputs& in = inputs();
  std::string seqs;
  for (size_t i = 0; i < std::min<size_t>(2, in.ground_truth.size()); ++i) seqs += " " + in.ground_truth[i];
  const fs::path page = in.dir / "viewer.html";
  // Marks of a directed run: the left hand off the object early, the right wrist pinned above it.
  const Sequence first = read_sequence(in.ground_truth.front());
  const at::Tensor above = first.object_states[10].slice(0, 4, 7).to(at::kDouble) + at::tensor({0.0, 0.1, 0.0}, at::kDouble);
  const fs::path hands = in.dir / "hands.yaml";
  std::ofstream(hands) << "hands:\n  left:\n    - frames: [0, 5]\n      part: none\n  right:\n    - frame: 10\n      wrist: ["
                       << above[0].item<double>() << ", " << above[1].item<double>() << ", " << above[2].item<double>()
                       << "]\n";
  const auto v = test::run_bimart("view" + seqs + " --measure-contacts --hands " + hands.string() + " --out " + page.string());
  ASSERT_EQ(v.status, 0) << v.output;
  std::printf("%s", v.output.c_str());
  const std::string shot = (fs::path(BIMART_TEST_WORK_DIR) / "viewer_screenshot.png").string();
  const Shell r = shell("NODE_PATH=" BIMART_TEST_NPM_DIR "/node_modules node " BIMART_TEST_SOURCE_DIR "/viewer_check.js " +
                        page.string() + " " + shot);
  std::printf("%s", r.output.c_str());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("console errors: 0, network requests: 0"), std::string::npos);
  EXPECT_NE(r.output.find("marks at pinned frame 10: {\"marks\":2,\"pins\":1"), std::string::npos);
  EXPECT_GT(fs::file_size(shot), 10000u);
}

}  // namespace
}  // namespace bimart
