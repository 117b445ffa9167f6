// The canonical pose about the hinge (core/object/canonical_frame.h): an object turned about
// its hinge any way comes back to the same canonical object, with states that keep every
// frame's world geometry, so the models see one frame however the object arrives. (The
// procedural families are not all in it: their turn to it is printed, up to 25°.)
#include "core/object/canonical_frame.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/data/turned_dataset.h"
#include "core/object/families/families.h"
#include "core/object/object_import.h"
#include "core/object/object_io.h"
#include "core/object/object_state.h"

namespace bimart {
namespace {

TriangleMesh moved(TriangleMesh m, const Eigen::Isometry3d& t) {
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) m.vertices.row(i) = (t * Eigen::Vector3d(m.vertices.row(i))).transpose();
  return m;
}

TEST(CanonicalFrame, TurnedCopiesComeBackToTheSameObject) {
  for (const std::string& category : object_categories()) {
    const ArticulatedObject o = make_object(category, 3);
    const Eigen::Isometry3d own = canonical_pose_about_hinge(o.top, o.bottom, 0.3);
    std::printf("%-16s turned %6.1f deg to the canonical pose\n", category.c_str(),
                std::atan2(own.linear()(1, 0), own.linear()(0, 0)) * 180 / M_PI);
    const TriangleMesh top0 = moved(o.top, own), bottom0 = moved(o.bottom, own);
    for (double deg : {90.0, 180.0, 270.0, 37.0}) {
      const ArticulatedObject t = turned_object(o, deg * M_PI / 180);
      const Eigen::Isometry3d c = canonical_pose_about_hinge(t.top, t.bottom, 0.3);
      EXPECT_LT((moved(t.top, c).vertices - top0.vertices).cwiseAbs().maxCoeff(), 1e-9) << category << " " << deg;
      EXPECT_LT((moved(t.bottom, c).vertices - bottom0.vertices).cwiseAbs().maxCoeff(), 1e-9) << category << " " << deg;
    }
  }
}

// Both parts posed in the world by states row `t`.
Eigen::MatrixXd world_vertices(const ArticulatedObject& o, const at::Tensor& states, std::int64_t t) {
  const at::Tensor row = states[t].to(at::kDouble).contiguous();
  const PosedObject p = pose_world(o, ObjectState::from_row(row.data_ptr<double>()));
  Eigen::MatrixXd v(p.top.rows() + p.bottom.rows(), 3);
  v << p.top, p.bottom;
  return v;
}

TEST(CanonicalFrame, ToCanonicalKeepsTheWorldGeometryOfEveryFrame) {
  const ArticulatedObject o = make_object("espressomachine", 2);  // 17 deg off the canonical pose
  at::manual_seed(3);
  at::Tensor states = at::randn({5, 7}, at::kDouble) * 0.5;
  states.select(1, 0).uniform_(0.0, 1.0);  // hinge angles
  const CanonicalObject ref = to_canonical(o);
  EXPECT_TRUE(ref.moved);
  for (double deg : {0.0, 90.0, 180.0, 270.0, 11.0}) {
    const double phi = deg * M_PI / 180;
    const ArticulatedObject t = turned_object(o, phi);
    at::Tensor ts = states.clone();
    for (std::int64_t f = 0; f < 5; ++f) {
      const at::Tensor row = states[f].contiguous();
      const ObjectState s = turned_state(ObjectState::from_row(row.data_ptr<double>()), phi);
      ts[f].copy_(at::tensor({s.angle, s.root_rotation.x(), s.root_rotation.y(), s.root_rotation.z(),
                              s.root_translation.x(), s.root_translation.y(), s.root_translation.z()},
                             at::kDouble));
    }
    const CanonicalObject c = to_canonical(t);
    EXPECT_LT((c.object.top.vertices - ref.object.top.vertices).cwiseAbs().maxCoeff(), 1e-9) << deg;
    EXPECT_LT((c.object.bottom.vertices - ref.object.bottom.vertices).cwiseAbs().maxCoeff(), 1e-9) << deg;
    const at::Tensor cs = canonical_states(ts, c.from_source);
    EXPECT_EQ(cs.scalar_type(), at::kDouble);
    EXPECT_TRUE(cs.select(1, 0).equal(ts.select(1, 0))) << "the hinge angle keeps its value";
    for (std::int64_t f = 0; f < 5; ++f) {
      // The world geometry: the file's (turned object, turned states) and the canonical one agree.
      EXPECT_LT((world_vertices(c.object, cs, f) - world_vertices(t, ts, f)).cwiseAbs().maxCoeff(), 1e-9) << deg;
      // And so do the canonical states of every turn (the models' input).
      EXPECT_LT((world_vertices(ref.object, cs, f) - world_vertices(o, states, f)).cwiseAbs().maxCoeff(), 1e-9) << deg;
      EXPECT_LT((cs[f] - canonical_states(states, ref.from_source)[f]).abs().max().item<double>(), 1e-9) << deg;
    }
  }
  // A canonical object stays as it is, bit for bit.
  const CanonicalObject again = to_canonical(ref.object);
  EXPECT_FALSE(again.moved);
  EXPECT_TRUE(again.object.top.vertices == ref.object.top.vertices);
}

// Issue 38: the same object arriving as an ARCTIC template folder (millimetres, hinge along
// -z, turned any way about it) and through `object import` (the same files, the hinge given)
// becomes the same canonical object.
TEST(CanonicalFrame, ArcticFolderAndImportGiveTheSameCanonicalObject) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "bimart_canonical_arctic_vs_import";
  fs::remove_all(dir);
  const fs::path box = dir / "box";  // an ARCTIC category name
  fs::create_directories(box);
  const ArticulatedObject o = turned_object(make_object("box", 5), 2.2);
  for (const auto& [mesh, file] : {std::pair{&o.top, "top.obj"}, {&o.bottom, "bottom.obj"}}) {
    TriangleMesh mm = *mesh;
    mm.vertices *= 1000.0;
    write_obj(mm, (box / file).string());
  }
  const CanonicalObject arctic = to_canonical(load_object(box.string()));
  EXPECT_TRUE(arctic.moved);
  ImportOptions opt;
  opt.top = (box / "top.obj").string();
  opt.bottom = (box / "bottom.obj").string();
  opt.units = "mm";
  opt.hinge.direction = Eigen::Vector3d(0, 0, -1);
  const ArticulatedObject imported = import_object(opt);
  const CanonicalObject again = to_canonical(imported);
  EXPECT_FALSE(again.moved) << "an imported object is canonical already";
  ASSERT_EQ(arctic.object.top.num_vertices(), imported.top.num_vertices());
  ASSERT_EQ(arctic.object.bottom.num_vertices(), imported.bottom.num_vertices());
  EXPECT_LT((arctic.object.top.vertices - imported.top.vertices).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((arctic.object.bottom.vertices - imported.bottom.vertices).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_TRUE(arctic.object.top.faces == imported.top.faces);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace bimart
