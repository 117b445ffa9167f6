// trajectory.file in a pipeline, the shipped example trajectories, and `bimart object import`,
// through the real program.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/object/object_io.h"
#include "core/object/families/families.h"
#include "core/trajectory/trajectory.h"
#include "core/trajectory/trajectory_object.h"
#include "core/trajectory/validation.h"
#include "tests/cli/run_bimart.h"

namespace bimart {
namespace {

namespace fs = std::filesystem;
using test::run_bimart;

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("bimart_trajectory_stage_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string example(const std::string& name) {
  return std::string(BIMART_SOURCE_DIR) + "/examples/trajectories/" + name;
}

int exit_code(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

TEST(TrajectoryStage, PluginsShowItsParameters) {
  const auto r = run_bimart("plugins --kind trajectory");
  ASSERT_EQ(exit_code(r.status), 0) << r.output;
  EXPECT_NE(r.output.find("trajectory.file  (kind trajectory)"), std::string::npos) << r.output;
  for (const char* p : {"path", "object", "category", "seed", "fps", "object_dir"})
    EXPECT_NE(r.output.find(std::string("param  ") + p), std::string::npos) << p << "\n" << r.output;
  EXPECT_NE(r.output.find("object_path"), std::string::npos) << r.output;
}

TEST(TrajectoryStage, RunsTheFirstExampleInAPipeline) {
  const fs::path dir = scratch("run");
  const fs::path yaml = dir / "p.yaml";
  std::ofstream(yaml) << "stages:\n"
                      << "  - id: trajectory\n    use: trajectory.file\n    params:\n"
                      << "      path: " << example("laptop_lift_open.yaml") << "\n"
                      << "      object_dir: " << (dir / "object").string() << "\n"
                      << "  - id: write\n    use: export.states_csv\n    params:\n"
                      << "      path: " << (dir / "states.csv").string() << "\n";
  const auto r = run_bimart("-q run " + yaml.string());
  ASSERT_EQ(exit_code(r.status), 0) << r.output;
  // What the stage wrote equals what the file says, to float32 precision; the CSV that
  // export.states_csv writes reads back as a trajectory.
  const Trajectory expected = read_trajectory(example("laptop_lift_open.yaml"));
  const Trajectory got = read_trajectory((dir / "states.csv").string());
  ASSERT_EQ(got.num_frames(), expected.num_frames());
  EXPECT_NEAR(got.fps, 30, 1e-6);
  EXPECT_LT((got.states - expected.states).cwiseAbs().maxCoeff(), 1e-6);
  // The procedural object went where asked, for exporters.
  EXPECT_TRUE(fs::exists(dir / "object" / "object.yaml"));
  EXPECT_EQ(load_object((dir / "object").string()).name, "laptop_3");
}

TEST(TrajectoryStage, BadKeyframesStopTheRunBeforeAnyStageRuns) {
  const fs::path dir = scratch("bad");
  const fs::path keys = dir / "keys.yaml";
  std::ofstream(keys) << "object: {category: box, seed: 1}\nkeys:\n  - t: 0\n    angle: 0\n  - t: 2\n    angle: 170\n";
  const fs::path yaml = dir / "p.yaml";
  std::ofstream(yaml) << "stages:\n  - id: trajectory\n    use: trajectory.file\n    params:\n      path: " << keys.string()
                      << "\n  - id: write\n    use: export.states_csv\n    params:\n      path: "
                      << (dir / "states.csv").string() << "\n";
  const auto r = run_bimart("run " + yaml.string());
  EXPECT_EQ(exit_code(r.status), 1) << r.output;
  EXPECT_NE(r.output.find(keys.string() + ":5:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("outside the limits [0, 110] deg"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "states.csv"));
}

TEST(TrajectoryStage, ShippedExamplesHoldTheirObjectsLimits) {
  struct Case {
    const char* file;
    const char* category;
    std::int64_t min_frames, max_frames;
  };
  for (const Case& c : {Case{"laptop_lift_open.yaml", "laptop", 64, 90}, Case{"box_carry_open.yaml", "box", 90, 240},
                        Case{"ketchup_flip_cap.yaml", "ketchup", 60, 240}}) {
    const Trajectory tr = read_trajectory(example(c.file));
    EXPECT_TRUE(tr.from_keyframes) << c.file;
    EXPECT_EQ(tr.object.category, c.category) << c.file;
    EXPECT_GE(tr.num_frames(), c.min_frames) << c.file;
    EXPECT_LE(tr.num_frames(), c.max_frames) << c.file;
    const TrajectoryObject o = resolve_trajectory_object({}, tr.object, example(c.file), scratch("examples").string());
    EXPECT_NO_THROW(validate_trajectory(tr, o.object)) << c.file;
    // The hinge opens by a good part of its range, and the object is on or above the table.
    EXPECT_GT(tr.states.col(0).maxCoeff(), 0.4 * o.object.angle_max) << c.file;
    EXPECT_GE(tr.states.col(5).minCoeff(), 0.0) << c.file;
  }
}

TEST(ObjectImportCli, ImportsAndReports) {
  const fs::path dir = scratch("import");
  // A lid and a base in millimetres, hinge along -x at the back top edge (y = 80, z = -100):
  // a positive angle about -x lifts the lid.
  write_obj(make_box({-150, 0, -100}, {150, 80, 100}), (dir / "base.obj").string());
  write_obj(make_box({-150, 80, -100}, {150, 90, 100}), (dir / "lid.obj").string());
  const std::string meshes = (dir / "lid.obj").string() + " " + (dir / "base.obj").string();
  auto r = run_bimart("object import " + meshes + " --top " + (dir / "lid.obj").string() +
                      " --pivot 0 80 -100 --axis -1 0 0 --units mm --category box --out " + (dir / "out").string());
  ASSERT_EQ(exit_code(r.status), 0) << r.output;
  EXPECT_NE(r.output.find("8 vertices, 12 faces, closed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("size    0.3 m"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("wrote out to"), std::string::npos) << r.output;
  const ArticulatedObject o = load_object((dir / "out").string());
  EXPECT_NEAR(o.top.vertices.col(1).minCoeff(), 0.0, 1e-9);  // the lid sits on y = 0 above the base
  EXPECT_NEAR(o.bottom.vertices.col(1).maxCoeff(), 0.0, 1e-9);
  EXPECT_NEAR(o.bottom.vertices.col(0).minCoeff(), -0.2, 1e-9);  // extends towards -x from the hinge
  // Errors: an existing object without --force, --top naming neither mesh, no hinge.
  r = run_bimart("object import " + meshes + " --top " + (dir / "lid.obj").string() +
                 " --pivot 0 80 -100 --axis 1 0 0 --units mm --out " + (dir / "out").string());
  EXPECT_EQ(exit_code(r.status), 1) << r.output;
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  r = run_bimart("object import " + meshes + " --top other.obj --pivot 0 0 0 --axis 1 0 0 --out " +
                 (dir / "out2").string());
  EXPECT_EQ(exit_code(r.status), 1) << r.output;
  EXPECT_NE(r.output.find("neither of the two mesh files"), std::string::npos) << r.output;
  r = run_bimart("object import " + meshes + " --top " + (dir / "lid.obj").string() + " --out " + (dir / "out3").string());
  EXPECT_EQ(exit_code(r.status), 1) << r.output;
  EXPECT_NE(r.output.find("give the hinge"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out3" / "object.yaml"));
}

}  // namespace
}  // namespace bimart
