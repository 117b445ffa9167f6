// Trajectory files: per-frame CSV / YAML / npz round trips, keyframe YAML, and every
// validation error naming the file and line.
#include <gtest/gtest.h>

#include <ATen/ATen.h>
#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "core/io/sequence.h"
#include "core/object/families/families.h"
#include "core/object/object_io.h"
#include "core/trajectory/trajectory.h"
#include "core/trajectory/trajectory_object.h"
#include "core/trajectory/validation.h"
#include "tests/error_of.h"

using bimart::test::error_of;

namespace bimart {
namespace {

namespace fs = std::filesystem;

class TrajectoryFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("bimart_trajectory_files_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) const {
    const std::string p = (dir_ / name).string();
    std::ofstream(p) << text;
    return p;
  }
  fs::path dir_;
};

StateRows random_states(Eigen::Index n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  StateRows s(n, 7);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int c = 0; c < 7; ++c) s(i, c) = c == 0 ? 0.5 + 0.4 * u(rng) : u(rng);
  return s;
}

TEST_F(TrajectoryFiles, CsvRoundTrip) {
  const StateRows s = random_states(50, 1);
  std::string text = "# my trajectory\n# fps: 60\n# category: laptop\n# seed: 4\n\nangle,rx,ry,rz,tx,ty,tz\n";
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    for (int c = 0; c < 7; ++c) text += fmt::format("{}{:.17g}", c ? "," : "", s(i, c));
    text += "\n";
  }
  const Trajectory tr = read_trajectory(write("a.csv", text));
  EXPECT_EQ(tr.fps, 60);
  EXPECT_EQ(tr.object.category, "laptop");
  EXPECT_EQ(tr.object.seed, 4);
  ASSERT_EQ(tr.num_frames(), 50);
  EXPECT_EQ(tr.states, s);
  EXPECT_EQ(tr.lines[0][0], 7);
  // Columns in another order, with frame and time columns (what export.states_csv writes).
  std::string timed = "frame,time,tz,ty,tx,rz,ry,rx,angle\n";
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    timed += fmt::format("{},{:.9g}", i, i / 25.0);
    for (int c = 6; c >= 0; --c) timed += fmt::format(",{:.17g}", s(i, c));
    timed += "\n";
  }
  const Trajectory t2 = read_trajectory(write("b.csv", timed));
  EXPECT_NEAR(t2.fps, 25, 1e-6);
  EXPECT_EQ(t2.states, s);
  EXPECT_TRUE(t2.object.empty());
  // The stage's fps wins.
  EXPECT_EQ(read_trajectory(write("c.csv", timed), 50).fps, 50);
}

TEST_F(TrajectoryFiles, YamlFramesRoundTrip) {
  const StateRows s = random_states(12, 2);
  std::string text = "fps: 24\nobject: ../objects/box\nframes:\n";
  for (Eigen::Index i = 0; i < s.rows(); ++i) {
    text += "  - [";
    for (int c = 0; c < 7; ++c) text += fmt::format("{}{:.17g}", c ? ", " : "", s(i, c));
    text += "]\n";
  }
  const Trajectory tr = read_trajectory(write("a.yaml", text));
  EXPECT_EQ(tr.fps, 24);
  EXPECT_EQ(tr.object.path, "../objects/box");
  EXPECT_EQ(tr.object.where.line, 2);
  EXPECT_EQ(tr.states, s);
  EXPECT_EQ(tr.lines[3][0], 7);
  EXPECT_FALSE(tr.from_keyframes);
}

TEST_F(TrajectoryFiles, NpzRoundTrip) {
  Sequence seq;
  seq.name = "t";
  seq.object = "objects/laptop_1";
  seq.fps = 15;
  seq.object_states = at::rand({20, 7});
  for (auto& h : seq.hands.hands) {
    h.rot = at::zeros({20, 3});
    h.pose = at::zeros({20, 45});
    h.trans = at::zeros({20, 3});
    h.shape = at::zeros({10});
  }
  const std::string path = (dir_ / "s.npz").string();
  write_sequence(seq, path);
  const Trajectory tr = read_trajectory(path);
  EXPECT_EQ(tr.fps, 15);
  EXPECT_EQ(tr.object.path, "objects/laptop_1");
  ASSERT_EQ(tr.num_frames(), 20);
  const auto a = seq.object_states.accessor<float, 2>();
  for (int i = 0; i < 20; ++i)
    for (int c = 0; c < 7; ++c) EXPECT_EQ(tr.states(i, c), static_cast<double>(a[i][c]));
}

TEST_F(TrajectoryFiles, KeyframesFromYaml) {
  const std::string path = write("k.yaml",
                                 "object: {category: box, seed: 2}\n"
                                 "fps: 10\n"
                                 "keys:\n"
                                 "  - t: 0\n"
                                 "    position: [0, 0, 0]\n"
                                 "    rotation: {euler_xyz: [0, 0, 0]}\n"
                                 "    angle: 0\n"
                                 "  - t: 1\n"
                                 "    rotation: {axis_angle: [0, 90, 0]}\n"
                                 "  - t: 2\n"
                                 "    position: [0, 0.3, 0]\n"
                                 "    angle: 60\n");
  const Trajectory tr = read_trajectory(path);
  EXPECT_TRUE(tr.from_keyframes);
  EXPECT_EQ(tr.fps, 10);
  ASSERT_EQ(tr.num_frames(), 21);
  EXPECT_EQ(tr.object.category, "box");
  EXPECT_EQ(tr.object.seed, 2);
  EXPECT_NEAR(tr.states(20, 0), M_PI / 3, 1e-12);
  EXPECT_NEAR(tr.states(10, 2), M_PI / 2, 1e-12);  // 90 deg about y at t = 1
  EXPECT_NEAR(tr.states(20, 5), 0.3, 1e-12);
  EXPECT_EQ(read_trajectory(path, 30).num_frames(), 61);  // the stage's fps wins
  // The frames say where they came from.
  EXPECT_EQ(tr.lines[15][0], 4);
  EXPECT_EQ(tr.lines[15][1], 10);
  EXPECT_NE(tr.describe_frame(15).find("between the keys at lines 4 and 10"), std::string::npos);
}

struct BadCase {
  const char* name;
  const char* file;
  const char* text;
  const char* where;    // "file:line" expected at the start
  const char* message;  // part of the message
};

TEST_F(TrajectoryFiles, EveryErrorNamesFileAndLine) {
  const std::vector<BadCase> cases = {
      {"nan key", "a.yaml", "keys:\n  - t: 0\n    angle: 0\n  - t: 1\n    angle: .nan\n", "a.yaml:5", "not a finite number"},
      {"inf position", "a.yaml", "keys:\n  - t: 0\n    position: [0, .inf, 0]\n  - t: 1\n    angle: 1\n", "a.yaml:3",
       "not a finite number"},
      {"nan csv", "a.csv", "angle,rx,ry,rz,tx,ty,tz\n0,0,0,0,0,0,0\n0,0,nan,0,0,0,0\n", "a.csv:3", "column 'ry'"},
      {"inf frame", "a.yaml", "frames:\n  - [0, 0, 0, 0, 0, 0, 0]\n  - [0, 0, 0, 0, 0, -.inf, 0]\n", "a.yaml:3",
       "ty is not a finite"},
      {"times", "a.yaml", "keys:\n  - t: 0\n    angle: 0\n  - t: 1\n    angle: 1\n  - t: 1\n    angle: 2\n", "a.yaml:6",
       "strictly increase"},
      {"one key", "a.yaml", "keys:\n  - t: 0\n    angle: 0\n", "a.yaml:2", "at least 2 keys"},
      {"one frame", "a.yaml", "fps: 30\nkeys:\n  - t: 0\n    angle: 0\n  - t: 0.01\n    angle: 1\n", "a.yaml:5",
       "at least 2 frames"},
      {"one row", "a.csv", "angle,rx,ry,rz,tx,ty,tz\n0,0,0,0,0,0,0\n", "a.csv:2", "at least 2 frames"},
      {"too long", "a.yaml", "keys:\n  - t: 0\n    angle: 0\n  - t: 601\n    angle: 1\n", "a.yaml:4",
       "at most 18000 frames"},
      {"unknown top key", "a.yaml", "keyz:\n  - t: 0\n", "a.yaml:1", "did you mean 'keys'"},
      {"unknown key field", "a.yaml", "keys:\n  - t: 0\n    positon: [0, 0, 0]\n", "a.yaml:3", "did you mean 'position'"},
      {"unknown column", "a.csv", "angle,rx,ry,rz,tx,ty,tzz\n", "a.csv:1", "unknown column 'tzz'"},
      {"missing column", "a.csv", "angle,rx,ry,rz,tx,ty\n", "a.csv:1", "no column 'tz'"},
      {"row width", "a.csv", "angle,rx,ry,rz,tx,ty,tz\n0,0,0\n", "a.csv:2", "3 values"},
      {"not a number", "a.yaml", "keys:\n  - t: soon\n    angle: 0\n", "a.yaml:2", "t must be a number, got 'soon'"},
      {"short vector", "a.yaml", "keys:\n  - t: 0\n    position: [0, 1]\n", "a.yaml:3", "list of 3 numbers"},
      {"rest type", "a.yaml", "rest: maybe\nkeys:\n  - t: 0\n    angle: 0\n  - t: 1\n    angle: 0\n", "a.yaml:1",
       "rest must be true or false"},
      {"euler order", "a.yaml", "keys:\n  - t: 0\n    rotation: {euler_xxy: [0, 0, 0]}\n", "a.yaml:3",
       "unknown rotation 'euler_xxy'"},
      {"empty key", "a.yaml", "keys:\n  - t: 0\n  - t: 1\n    angle: 0\n", "a.yaml:2", "gives none of"},
      {"duplicate", "a.yaml", "fps: 30\nfps: 60\nkeys: []\n", "a.yaml:2", "given twice (first at line 1)"},
      {"frame width", "a.yaml", "frames:\n  - [0, 0, 0]\n  - [0, 0, 0, 0, 0, 0, 0]\n", "a.yaml:2", "list of 7 numbers"},
      {"both", "a.yaml", "frames: []\nkeys: []\n", "a.yaml:2", "not both"},
      {"object", "a.yaml", "object: {category: box, path: x}\nkeys: []\n", "a.yaml:1", "either path or category"},
      {"syntax", "a.yaml", "keys: [\n", "a.yaml:2", ""},
  };
  for (const BadCase& c : cases) {
    const std::string path = write(c.file, c.text);
    const std::string e = error_of([&] { read_trajectory(path); });
    EXPECT_EQ(e.rfind(path.substr(0, path.size() - std::string(c.file).size()) + c.where + ":", 0), 0u)
        << c.name << ": " << e;
    EXPECT_NE(e.find(c.message), std::string::npos) << c.name << ": " << e;
  }
}

TEST_F(TrajectoryFiles, TooManyCsvRowsStopAtTheFirstOneOver) {
  std::string text = "angle,rx,ry,rz,tx,ty,tz\n";
  for (int i = 0; i < kMaxTrajectoryFrames + 5; ++i) text += "0,0,0,0,0,0,0\n";
  const std::string path = write("long.csv", text);
  const std::string e = error_of([&] { read_trajectory(path); });
  EXPECT_EQ(e.rfind(path + ":18002:", 0), 0u) << e;
  EXPECT_NE(e.find("at most 18000 frames"), std::string::npos) << e;
}

TEST_F(TrajectoryFiles, HingeLimitsAreCheckedAgainstTheObject) {
  const ArticulatedObject laptop = make_object("laptop", 0);  // 0 - 135 deg
  // A key beyond the limit names the key's line.
  std::string path = write("k.yaml", "keys:\n  - t: 0\n    angle: 0\n  - t: 1\n    angle: 150\n");
  std::string e = error_of([&] { validate_trajectory(read_trajectory(path), laptop); });
  EXPECT_EQ(e.rfind(path + ":4:", 0), 0u) << e;
  EXPECT_NE(e.find("150 deg of this key is outside the limits [0, 135] deg"), std::string::npos) << e;
  // Keys within the limits whose spline overshoots: the frame and the keys around it.
  path = write("o.yaml", "keys:\n  - t: 0\n    angle: 0\n  - t: 1\n    angle: 135\n  - t: 3\n    angle: 135\n");
  e = error_of([&] { validate_trajectory(read_trajectory(path), laptop); });
  EXPECT_EQ(e.rfind(path + ":4:", 0), 0u) << e;
  EXPECT_NE(e.find("between the keys at lines 4 and 6"), std::string::npos) << e;
  EXPECT_NE(e.find("overshoots"), std::string::npos) << e;
  // A per-frame file names the row's line.
  path = write("f.csv", "angle,rx,ry,rz,tx,ty,tz\n0,0,0,0,0,0,0\n-0.1,0,0,0,0,0,0\n");
  e = error_of([&] { validate_trajectory(read_trajectory(path), laptop); });
  EXPECT_EQ(e.rfind(path + ":3:", 0), 0u) << e;
  EXPECT_NE(e.find("frame 1: the hinge angle -5.73 deg"), std::string::npos) << e;
  // Within the limits: fine.
  path = write("g.yaml", "keys:\n  - t: 0\n    angle: 0\n  - t: 1\n    angle: 135\n");
  EXPECT_EQ(error_of([&] { validate_trajectory(read_trajectory(path), laptop); }), "");
}

TEST_F(TrajectoryFiles, ObjectsResolveAgainstTheTrajectoryFolder) {
  const ArticulatedObject box = make_object("box", 1);
  save_object(box, (dir_ / "objects" / "box").string());
  fs::create_directories(dir_ / "traj");
  const std::string path = write("traj/a.yaml", "object: ../objects/box\nkeys:\n  - t: 0\n    angle: 0\n  - t: 1\n    angle: 1\n");
  const Trajectory tr = read_trajectory(path);
  TrajectoryObject o = resolve_trajectory_object({}, tr.object, path, "");
  EXPECT_FALSE(o.procedural);
  EXPECT_EQ(o.path, (dir_ / "objects" / "box").lexically_normal().string());
  EXPECT_EQ(o.object.top.num_vertices(), box.top.num_vertices());
  // The stage's category wins and is written where asked.
  ObjectReference chosen;
  chosen.category = "ketchup";
  chosen.seed = 3;
  o = resolve_trajectory_object(chosen, tr.object, path, (dir_ / "made").string());
  EXPECT_TRUE(o.procedural);
  EXPECT_EQ(o.object.name, "ketchup_3");
  save_trajectory_object(o);
  EXPECT_TRUE(fs::exists(dir_ / "made" / "object.yaml"));
  // Errors name where the object was named.
  const std::string bad = write("traj/b.yaml", "object: {category: laptp}\nkeys:\n  - t: 0\n    angle: 0\n  - t: 1\n    angle: 1\n");
  std::string e = error_of([&] { resolve_trajectory_object({}, read_trajectory(bad).object, bad, ""); });
  EXPECT_EQ(e.rfind(bad + ":1:", 0), 0u) << e;
  EXPECT_NE(e.find("laptop"), std::string::npos) << e;
  e = error_of([&] { resolve_trajectory_object({}, ObjectReference{}, bad, ""); });
  EXPECT_NE(e.find("names no object"), std::string::npos) << e;
  const std::string missing = write("traj/c.yaml", "object: nowhere\nkeys:\n  - t: 0\n    angle: 0\n  - t: 1\n    angle: 1\n");
  e = error_of([&] { resolve_trajectory_object({}, read_trajectory(missing).object, missing, ""); });
  EXPECT_EQ(e.rfind(missing + ":1:", 0), 0u) << e;
}

}  // namespace
}  // namespace bimart
