// bimart object import: a box we build, written as meshes in millimetres in an arbitrary
// frame with its hinge, comes back as the same canonical object; bad meshes and hinges fail
// with clear messages.
#include "core/object/object_import.h"

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <tuple>

#include "core/geometry/rotation.h"
#include "core/object/mesh_repair.h"
#include "core/object/object_io.h"
#include "core/object/object_state.h"
#include "core/util/error.h"
#include "tests/error_of.h"

using bimart::test::error_of;

namespace bimart {
namespace {

namespace fs = std::filesystem;

// A closed box with a lid in the canonical frame of the families: hinge on -z through the
// origin, extending towards -x, base below y = 0, lid above, centred along z.
ArticulatedObject canonical_box() {
  ArticulatedObject o;
  o.name = "test_box";
  o.bottom = make_box({-0.24, -0.12, -0.15}, {0, 0, 0.15});
  o.top = make_box({-0.24, 0, -0.15}, {0, 0.015, 0.15});
  return o;
}

class ObjectImport : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("bimart_object_import_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    pose_.linear() = axis_angle_to_matrix(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 2.5);
    pose_.translation() = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.8;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // The mesh moved by pose_, in millimetres, as OBJ, ASCII PLY or ASCII STL (by extension).
  std::string write_mesh(const TriangleMesh& m, const std::string& name, int skip_face = -1) const {
    const std::string p = path(name);
    std::ofstream out(p);
    std::vector<Eigen::Vector3d> v;
    for (Eigen::Index i = 0; i < m.num_vertices(); ++i) v.push_back(1000 * (pose_ * Eigen::Vector3d(m.vertices.row(i))));
    std::vector<Eigen::Vector3i> f;
    for (Eigen::Index i = 0; i < m.num_faces(); ++i)
      if (i != skip_face) f.push_back(m.faces.row(i));
    const std::string ext = fs::path(name).extension().string();
    if (ext == ".obj") {
      for (const auto& x : v) out << fmt::format("v {:.17g} {:.17g} {:.17g}\n", x.x(), x.y(), x.z());
      for (const auto& t : f) out << fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    } else if (ext == ".ply") {
      out << "ply\nformat ascii 1.0\nelement vertex " << v.size() << "\nproperty double x\nproperty double y\n"
          << "property double z\nelement face " << f.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
      for (const auto& x : v) out << fmt::format("{:.17g} {:.17g} {:.17g}\n", x.x(), x.y(), x.z());
      for (const auto& t : f) out << fmt::format("3 {} {} {}\n", t[0], t[1], t[2]);
    } else {
      out << "solid part\n";
      for (const auto& t : f) {
        out << "facet normal 0 0 0\nouter loop\n";
        for (int c = 0; c < 3; ++c) out << fmt::format("vertex {:.17g} {:.17g} {:.17g}\n", v[t[c]].x(), v[t[c]].y(), v[t[c]].z());
        out << "endloop\nendfacet\n";
      }
      out << "endsolid part\n";
    }
    return p;
  }

  // The hinge in the files' frame (mm): the point (0, 0, z) of the canonical axis, and its
  // direction -z scaled by `length`.
  HingeAxis file_hinge(double z = 0.37, double length = 5) const {
    return {1000 * (pose_ * Eigen::Vector3d(0, 0, z)), pose_.linear() * Eigen::Vector3d(0, 0, -length)};
  }

  ImportOptions options(const std::string& top, const std::string& bottom) const {
    ImportOptions o;
    o.top = top;
    o.bottom = bottom;
    o.hinge = file_hinge();
    o.units = "mm";
    o.name = "imported_box";
    return o;
  }

  fs::path dir_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
};

// Largest distance (m) from a vertex of `a` to the nearest vertex of `b`.
double max_vertex_gap(const TriangleMesh& a, const TriangleMesh& b) {
  double worst = 0;
  for (Eigen::Index i = 0; i < a.num_vertices(); ++i)
    worst = std::max(worst, (b.vertices.rowwise() - a.vertices.row(i)).rowwise().norm().minCoeff());
  return worst;
}

TEST_F(ObjectImport, BoxInMillimetresComesBackCanonical) {
  const ArticulatedObject box = canonical_box();
  for (const auto& [top_name, bottom_name] : {std::pair{"lid.obj", "base.ply"}, {"lid.stl", "base.obj"}}) {
    ImportReport report;
    const ArticulatedObject o =
        import_object(options(write_mesh(box.top, top_name), write_mesh(box.bottom, bottom_name)), &report);
    EXPECT_LT(max_vertex_gap(o.top, box.top), 1e-4) << top_name;  // 0.1 mm
    EXPECT_LT(max_vertex_gap(box.top, o.top), 1e-4) << top_name;
    EXPECT_LT(max_vertex_gap(o.bottom, box.bottom), 1e-4) << bottom_name;
    EXPECT_LT(max_vertex_gap(box.bottom, o.bottom), 1e-4) << bottom_name;
    EXPECT_TRUE(is_closed_mesh(o.top));
    EXPECT_TRUE(is_closed_mesh(o.bottom));
    EXPECT_GT(signed_volume(o.bottom), 0);
    EXPECT_NEAR(object_scale(o), object_scale(box), 1e-6);
    EXPECT_NEAR(report.size, 0.3, 1e-6);
    EXPECT_TRUE(report.top.closed_as_read);
    EXPECT_EQ(report.top.vertices_read, 8);
    EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
    // Opening turns the lid up, away from the base (+y).
    EXPECT_GT(posed_top(o, 1.0).vertices.col(1).maxCoeff(), 0.15);
  }
}

TEST_F(ObjectImport, TwoPointsOnTheAxisGiveTheSameObject) {
  const ArticulatedObject box = canonical_box();
  ImportOptions o = options(write_mesh(box.top, "lid.obj"), write_mesh(box.bottom, "base.obj"));
  o.hinge = hinge_through(1000 * (pose_ * Eigen::Vector3d(0, 0, 0.5)), 1000 * (pose_ * Eigen::Vector3d(0, 0, -0.2)));
  const ArticulatedObject out = import_object(o);
  EXPECT_LT(max_vertex_gap(out.top, box.top), 1e-4);
  EXPECT_LT(max_vertex_gap(out.bottom, box.bottom), 1e-4);
}

TEST_F(ObjectImport, OneObjWithGroupsGivesTheSameObject) {
  const ArticulatedObject box = canonical_box();
  // Both parts in one file, the lid as group "lid", the base as "base"; an empty group last.
  std::ofstream out(path("both.obj"));
  out << "# exported\no box\n";
  for (const TriangleMesh* m : {&box.bottom, &box.top})
    for (Eigen::Index i = 0; i < m->num_vertices(); ++i) {
      const Eigen::Vector3d v = 1000 * (pose_ * Eigen::Vector3d(m->vertices.row(i)));
      out << fmt::format("v {:.17g} {:.17g} {:.17g}\n", v.x(), v.y(), v.z());
    }
  for (const auto& [name, m, offset] : {std::tuple{"base", &box.bottom, 1}, {"lid", &box.top, 9}}) {
    out << "g " << name << "\n";
    for (Eigen::Index f = 0; f < m->num_faces(); ++f)
      out << fmt::format("f {} {} {}\n", m->faces(f, 0) + offset, m->faces(f, 1) + offset, m->faces(f, 2) + offset);
  }
  out << "g other\n";
  out.close();
  ImportOptions o = options("", "");
  o.labelled = path("both.obj");
  o.top_label = "lid";
  ImportReport report;
  const ArticulatedObject imported = import_object(o, &report);
  EXPECT_EQ(report.top.vertices_read, 8);
  EXPECT_EQ(report.bottom.vertices_read, 8);
  EXPECT_LT(max_vertex_gap(imported.top, box.top), 1e-4);
  EXPECT_LT(max_vertex_gap(imported.bottom, box.bottom), 1e-4);
  // A label the file lacks names the groups it has.
  o.top_label = "cap";
  const std::string e = error_of([&] { import_object(o); });
  EXPECT_NE(e.find("no group 'cap' with faces (its groups: 'box', 'base', 'lid', 'other')"), std::string::npos) << e;
  o.labelled = write_mesh(box.top, "lid.stl");
  EXPECT_NE(error_of([&] { import_object(o); }).find("OBJ groups"), std::string::npos);
}

TEST_F(ObjectImport, HolesAreFilledAndReported) {
  const ArticulatedObject box = canonical_box();
  ImportReport report;
  const ArticulatedObject o =
      import_object(options(write_mesh(box.top, "lid.obj"), write_mesh(box.bottom, "base.obj", 3)), &report);
  EXPECT_FALSE(report.bottom.closed_as_read);
  EXPECT_EQ(report.bottom.repair.holes_filled, 1);
  EXPECT_TRUE(is_closed_mesh(o.bottom));
  EXPECT_NE(report.str().find("open; filled 1 hole"), std::string::npos) << report.str();
  EXPECT_NE(report.str().find("8 vertices, 11 faces"), std::string::npos) << report.str();
}

TEST_F(ObjectImport, ReversedAxisAndOddSizesWarn) {
  const ArticulatedObject box = canonical_box();
  ImportOptions o = options(write_mesh(box.top, "lid.obj"), write_mesh(box.bottom, "base.obj"));
  o.hinge.direction = -o.hinge.direction;
  ImportReport report;
  import_object(o, &report);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("reversed"), std::string::npos) << report.warnings[0];
  // The same numbers read as centimetres: a 3 m box, far outside the training sizes.
  o = options(o.top, o.bottom);
  o.units = "cm";
  import_object(o, &report);
  EXPECT_NEAR(report.size, 3.0, 1e-5);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("far outside"), std::string::npos) << report.warnings[0];
}

TEST_F(ObjectImport, BadHingesAndMeshesFailClearly) {
  const ArticulatedObject box = canonical_box();
  const std::string lid = write_mesh(box.top, "lid.obj"), base = write_mesh(box.bottom, "base.obj");
  ImportOptions o = options(lid, base);
  o.hinge.direction.setZero();
  EXPECT_NE(error_of([&] { import_object(o); }).find("the hinge direction is zero"), std::string::npos);
  o = options(lid, base);
  o.hinge = hinge_through(Eigen::Vector3d(5, 5, 5), Eigen::Vector3d(5, 5, 5));
  EXPECT_NE(error_of([&] { import_object(o); }).find("the hinge direction is zero"), std::string::npos);
  // A hinge 2 m away from the parts (moved perpendicular to the axis).
  o = options(lid, base);
  o.hinge.point += 2000 * (pose_.linear() * Eigen::Vector3d(1, 0, 0));
  std::string e = error_of([&] { import_object(o); });
  EXPECT_NE(e.find("from the hinge"), std::string::npos) << e;
  EXPECT_NE(e.find("lid.obj"), std::string::npos) << e;
  // Not a mesh; a missing file; wrong units (metres read as metres: 300 m).
  std::ofstream(path("junk.obj")) << "v 1 2 three\n";
  e = error_of([&] { import_object(options(path("junk.obj"), base)); });
  EXPECT_NE(e.find("junk.obj:1"), std::string::npos) << e;
  e = error_of([&] { import_object(options(path("none.stl"), base)); });
  EXPECT_NE(e.find("none.stl"), std::string::npos) << e;
  o = options(lid, base);
  o.units = "m";
  e = error_of([&] { import_object(o); });
  EXPECT_NE(e.find("wrong --units"), std::string::npos) << e;
  o.units = "inch";
  EXPECT_NE(error_of([&] { import_object(o); }).find("units must be m, cm or mm"), std::string::npos);
  // A flat part (one triangle) is no solid.
  TriangleMesh flat;
  flat.vertices.resize(3, 3);
  flat.vertices << 0, 0, 0, -0.1, 0, 0, 0, -0.1, 0;
  flat.faces.resize(1, 3);
  flat.faces << 0, 1, 2;
  e = error_of([&] { import_object(options(lid, write_mesh(flat, "flat.obj"))); });
  EXPECT_NE(e.find("flat.obj"), std::string::npos) << e;
}

TEST_F(ObjectImport, WrittenAtomicallyAndReadBack) {
  const ArticulatedObject box = canonical_box();
  ImportOptions opt = options(write_mesh(box.top, "lid.obj"), write_mesh(box.bottom, "base.obj"));
  opt.category = "box";
  const ArticulatedObject o = import_object(opt);
  EXPECT_NEAR(o.angle_max, 110 * M_PI / 180, 1e-12);  // the category's limits
  const std::string out = path("out/box");
  write_object_folder(o, out, false);
  const ArticulatedObject back = load_object(out);
  EXPECT_LT(max_vertex_gap(back.top, o.top), 1e-12);
  EXPECT_EQ(back.name, "imported_box");
  EXPECT_EQ(back.angle_max, o.angle_max);
  // An existing object needs force; a folder of other files is never replaced.
  EXPECT_NE(error_of([&] { check_object_output(out, false); }).find("--force"), std::string::npos);
  EXPECT_EQ(error_of([&] { write_object_folder(o, out, true); }), "");
  fs::create_directories(path("other"));
  std::ofstream(path("other/notes.txt")) << "mine";
  EXPECT_NE(error_of([&] { check_object_output(path("other"), true); }).find("no object.yaml"), std::string::npos);
  EXPECT_TRUE(fs::exists(path("other/notes.txt")));
  for (const auto& entry : fs::directory_iterator(path("out")))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST(TrainingSizes, TheDocumentedRangeHoldsTheFamilies) {
  const auto [lo, hi] = procedural_size_range(10);
  std::cout << fmt::format("procedural object sizes over seeds 0..9: {:.4f} - {:.4f} m\n", lo, hi);
  EXPECT_GE(lo, kTrainingSizeMin);
  EXPECT_LE(hi, kTrainingSizeMax);
  EXPECT_LT(lo, kTrainingSizeMin * 1.1);  // and the constants are close to the measurement
  EXPECT_GT(hi, kTrainingSizeMax / 1.1);
}

}  // namespace
}  // namespace bimart
