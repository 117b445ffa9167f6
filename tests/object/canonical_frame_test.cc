// The canonical pose about the hinge (core/object/canonical_frame.h): an object turned about
// its hinge any way comes back to the same canonical object — so canonicalising on arrival
// would make the models see one frame. (The procedural families are not all in it: their
// turn to it is printed, up to 25°; docs/objects.md.)
#include "core/object/canonical_frame.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/data/turned_dataset.h"
#include "core/object/families/families.h"

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

}  // namespace
}  // namespace bimart
