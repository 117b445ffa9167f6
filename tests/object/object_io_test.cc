#include "core/object/object_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/geometry/rotation.h"
#include "core/object/families/families.h"
#include "core/object/families/primitives.h"
#include "core/object/mesh_repair.h"
#include "core/object/object_state.h"
#include "core/util/error.h"
#include "tests/error_of.h"

using bimart::test::error_of;

namespace bimart {
namespace {

namespace fs = std::filesystem;

class ObjectIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("bimart_object_io_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(path(name)) << text; }
  // object.yaml naming top.obj and bottom.obj, plus `extra` lines.
  std::string yaml(const std::string& extra = "") const {
    write("object.yaml", "name: test\ntop: top.obj\nbottom: bottom.obj\n" + extra);
    return path("object.yaml");
  }
  fs::path dir_;
};

TEST_F(ObjectIo, SaveLoadRoundTrip) {
  const ArticulatedObject o = make_object("laptop", 3);
  save_object(o, dir_.string());
  ObjectLoadReport report;
  const ArticulatedObject back = load_object(dir_.string(), &report);
  EXPECT_FALSE(report.top.changed()) << report.str();
  EXPECT_FALSE(report.bottom.changed()) << report.str();
  EXPECT_EQ(back.name, o.name);
  EXPECT_EQ(back.category, "laptop");
  EXPECT_EQ(back.angle_min, o.angle_min);
  EXPECT_EQ(back.angle_max, o.angle_max);
  EXPECT_EQ(back.open_angle, o.open_angle);
  for (const auto& [a, b] : {std::pair{&o.top, &back.top}, {&o.bottom, &back.bottom}}) {
    ASSERT_EQ(a->num_vertices(), b->num_vertices());
    ASSERT_EQ(a->num_faces(), b->num_faces());
    EXPECT_LT((a->vertices - b->vertices).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_EQ(a->faces, b->faces);
  }
}

TEST_F(ObjectIo, MillimetresBecomeMetres) {
  write_obj(make_box({-100, 0, -50}, {0, 20, 50}), path("top.obj"));
  write_obj(make_box({-100, -30, -50}, {0, 0, 50}), path("bottom.obj"));
  const ArticulatedObject o = load_object(yaml("units: mm\n"));
  EXPECT_NEAR(o.top.vertices.col(0).minCoeff(), -0.1, 1e-15);
  EXPECT_NEAR(o.top.vertices.col(1).maxCoeff(), 0.02, 1e-15);
  EXPECT_NEAR(o.bottom.vertices.col(1).minCoeff(), -0.03, 1e-15);
  EXPECT_NEAR(object_scale(o), 0.85 / std::sqrt(0.01 + 0.0009 + 0.0025), 1e-12);
}

TEST_F(ObjectIo, HingeIsMovedToMinusZThroughTheOrigin) {
  const TriangleMesh top = make_box({0.1, 0.2, 0.3}, {0.3, 0.25, 0.4});
  write_obj(top, path("top.obj"));
  write_obj(make_box({0.1, 0.1, 0.3}, {0.3, 0.2, 0.4}), path("bottom.obj"));
  const Eigen::Vector3d pivot(0.1, 0.2, 0.3), axis(1, 0, 0);
  const ArticulatedObject o =
      load_object(yaml("hinge: {pivot: [0.1, 0.2, 0.3], axis: [1, 0, 0]}\nlimits: [0, 2]\n"));
  const Eigen::Matrix3d R = rotation_between(axis, Eigen::Vector3d(0, 0, -1));
  for (Eigen::Index i = 0; i < top.num_vertices(); ++i) {
    const Eigen::Vector3d expected = R * (Eigen::Vector3d(top.vertices.row(i)) - pivot);
    EXPECT_LT((Eigen::Vector3d(o.top.vertices.row(i)) - expected).norm(), 1e-12);
  }
  // A point on the old axis lands on -z.
  const Eigen::Vector3d on_axis = R * (pivot + 0.5 * axis - pivot);
  EXPECT_LT((on_axis - Eigen::Vector3d(0, 0, -0.5)).norm(), 1e-15);
  EXPECT_EQ(o.angle_max, 2.0);
  EXPECT_EQ(o.open_angle, 1.0);
}

TEST_F(ObjectIo, OpenBoxIsFilledAndClosed) {
  // A subdivided box without its top side (z = hi): one hole.
  const TriangleMesh box = shapes::rounded_box({-0.1, -0.05, -0.04}, {0.1, 0.05, 0.04}, 0.0, 0.01);
  TriangleMesh open = box;
  int kept = 0;
  for (Eigen::Index f = 0; f < box.num_faces(); ++f) {
    double zc = 0;
    for (int c = 0; c < 3; ++c) zc += box.vertices(box.faces(f, c), 2) / 3;
    if (zc < 0.04 - 1e-9) open.faces.row(kept++) = box.faces.row(f);
  }
  const int removed = static_cast<int>(box.num_faces()) - kept;
  open.faces.conservativeResize(kept, 3);
  ASSERT_GT(removed, 0);
  ASSERT_FALSE(is_closed_mesh(open));
  write_obj(open, path("top.obj"));
  write_obj(make_box({-0.1, -0.2, -0.04}, {0.1, -0.05, 0.04}), path("bottom.obj"));
  ObjectLoadReport report;
  const ArticulatedObject o = load_object(yaml(), &report);
  EXPECT_EQ(report.top.holes_filled, 1);
  EXPECT_GE(report.top.faces_added, 2);
  EXPECT_EQ(report.bottom.holes_filled, 0);
  EXPECT_TRUE(is_closed_mesh(o.top));
  // The filled lid is flat: the volume is the box's.
  EXPECT_NEAR(signed_volume(o.top), 0.2 * 0.1 * 0.08, 0.01 * 0.2 * 0.1 * 0.08);
  EXPECT_NE(report.str().find("filled 1 hole"), std::string::npos) << report.str();
}

TEST_F(ObjectIo, InwardFacesAreFlipped) {
  TriangleMesh inward = make_box({-0.2, 0, -0.1}, {0, 0.05, 0.1});
  inward.faces.col(1).swap(inward.faces.col(2));
  ASSERT_LT(signed_volume(inward), 0);
  write_obj(inward, path("top.obj"));
  write_obj(make_box({-0.2, -0.1, -0.1}, {0, 0, 0.1}), path("bottom.obj"));
  ObjectLoadReport report;
  const ArticulatedObject o = load_object(yaml(), &report);
  EXPECT_TRUE(report.top.reoriented);
  EXPECT_FALSE(report.bottom.reoriented);
  EXPECT_NEAR(signed_volume(o.top), 0.2 * 0.05 * 0.2, 1e-12);
}

TEST_F(ObjectIo, BadMeshesGiveErrorsNamingTheFile) {
  write_obj(make_box({-0.1, -0.1, -0.1}, {0, 0, 0.1}), path("bottom.obj"));
  const std::string top = path("top.obj");
  // Empty.
  write("top.obj", "# nothing\n");
  std::string msg = error_of([&] { load_object(yaml()); });
  EXPECT_NE(msg.find(top), std::string::npos) << msg;
  // A degenerate face (three points on a line) beside a valid one.
  write("top.obj", "v 0 0 0\nv 0.1 0 0\nv 0.2 0 0\nv 0 0.1 0\nf 1 2 4\nf 1 2 3\n");
  msg = error_of([&] { load_object(yaml()); });
  EXPECT_NE(msg.find(top), std::string::npos) << msg;
  EXPECT_NE(msg.find("face 1 is degenerate"), std::string::npos) << msg;
  // Not a number (the reader may refuse it, or the check catches it: either names the file).
  write("top.obj", "v 0 0 0\nv nan 0 0\nv 0 0.1 0\nf 1 2 3\n");
  msg = error_of([&] { load_object(yaml()); });
  EXPECT_NE(msg.find(top), std::string::npos) << msg;
  TriangleMesh nan_mesh = make_box({0, 0, 0}, {0.1, 0.1, 0.1});
  nan_mesh.vertices(3, 1) = std::numeric_limits<double>::quiet_NaN();
  msg = error_of([&] { validate_mesh(nan_mesh, "x.obj"); });
  EXPECT_NE(msg.find("x.obj: vertex 3 has a non-finite coordinate"), std::string::npos) << msg;
  // Absurd scale: a 10 m box given in metres, and a 4 mm box.
  write_obj(make_box({-10, 0, -10}, {0, 10, 10}), top);
  msg = error_of([&] { load_object(yaml()); });
  EXPECT_NE(msg.find(top), std::string::npos) << msg;
  EXPECT_NE(msg.find("units"), std::string::npos) << msg;
  write_obj(make_box({-4, 0, -2}, {0, 2, 2}), top);
  write_obj(make_box({-100, -100, -100}, {0, 0, 100}), path("bottom.obj"));
  msg = error_of([&] { load_object(yaml("units: mm\n")); });
  EXPECT_NE(msg.find(top), std::string::npos) << msg;
  // Missing file.
  fs::remove(top);
  msg = error_of([&] { load_object(yaml()); });
  EXPECT_NE(msg.find(top), std::string::npos) << msg;
}

TEST_F(ObjectIo, YamlMistakesNameTheLine) {
  write_obj(make_box({-0.1, 0, -0.1}, {0, 0.1, 0.1}), path("top.obj"));
  write_obj(make_box({-0.1, -0.1, -0.1}, {0, 0, 0.1}), path("bottom.obj"));
  std::string msg = error_of([&] { load_object(yaml("unit: mm\n")); });
  EXPECT_NE(msg.find("object.yaml:4:1: unknown field 'unit' (did you mean 'units'"), std::string::npos) << msg;
  msg = error_of([&] { load_object(yaml("units: inch\n")); });
  EXPECT_NE(msg.find("object.yaml:4:8: units must be m, cm or mm"), std::string::npos) << msg;
  msg = error_of([&] { load_object(yaml("limits: [2, 1]\n")); });
  EXPECT_NE(msg.find("min <= max"), std::string::npos) << msg;
}

TEST_F(ObjectIo, ArcticTemplateFolder) {
  const fs::path folder = dir_ / "laptop";
  fs::create_directories(folder);
  write_obj(make_box({-250, 0, -150}, {0, 8, 150}), (folder / "top.obj").string());
  write_obj(make_box({-250, -15, -150}, {0, 0, 150}), (folder / "bottom.obj").string());
  const ArticulatedObject o = load_object(folder.string());
  EXPECT_EQ(o.name, "laptop");
  EXPECT_EQ(o.angle_max, object_family("laptop").angle_max);
  EXPECT_NEAR(o.top.vertices.col(0).minCoeff(), -0.25, 1e-15);
  EXPECT_NEAR(o.bottom.vertices.col(1).minCoeff(), -0.015, 1e-15);
  EXPECT_NE(error_of([&] { load_object(dir_.string()); }).find("not an ARCTIC template folder"), std::string::npos);
}

}  // namespace
}  // namespace bimart
