// The geometry core refuses non-finite and absurd points with a bimart::Error before they
// reach CGAL (GMP raised SIGFPE on a NaN) or nanoflann.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <ATen/ATen.h>

#include "core/geometry/mesh_distance.h"
#include "core/geometry/nearest_points.h"
#include "core/geometry/point_guard.h"
#include "core/metrics/sequence_metrics.h"
#include "core/object/families/families.h"
#include "core/object/object_distance.h"
#include "core/object/object_state.h"
#include "core/util/error.h"
#include "tests/error_of.h"

using bimart::test::error_of;

namespace bimart {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(GeometryGuard, MeshDistanceRefusesNaNAndFarPoints) {
  const ArticulatedObject o = make_object("box", 1);
  const MeshDistance d(o.bottom);
  Points3 p = Points3::Zero(3, 3);
  p(1, 2) = kNaN;
  EXPECT_NE(error_of([&] { d.max_signed_distance(p); }).find("point 1 is (0, 0, nan): not finite"), std::string::npos);
  p(1, 2) = 0;
  p(2, 0) = 2e4;
  EXPECT_NE(error_of([&] { d.any_deeper_than(p, 0.01); }).find("more than 10000 m"), std::string::npos);
  EXPECT_NE(error_of([&] { d.query(Eigen::Vector3d(kNaN, 0, 0)); }).find("not finite"), std::string::npos);
  // Near the bound the answer is still a number: ~ the distance to the box.
  EXPECT_NEAR(d.signed_distance(Eigen::Vector3d(9999, 0, 0)), -9999, 1.0);
}

TEST(GeometryGuard, NearestPointsRefusesNaN) {
  Points3 p = Points3::Zero(2, 3);
  p(0, 0) = kNaN;
  EXPECT_NE(error_of([&] { NearestPoints n(p); }).find("nearest-point search: point 0"), std::string::npos);
  const NearestPoints ok(Points3::Zero(1, 3));
  EXPECT_NE(error_of([&] { ok.nearest(Eigen::Vector3d(0, kNaN, 0)); }).find("not finite"), std::string::npos);
}

TEST(GeometryGuard, ObjectStatesBeyondTheBoundAreRefused) {
  const double row[7] = {0, 1e30, 0, 0, 0, 0, 0};
  EXPECT_NE(error_of([&] { ObjectState::from_row(row); }).find("rx = 1e+30 is beyond the bound"), std::string::npos);
  const double fine[7] = {0.5, 999, 0, 0, -999, 0, 0};
  EXPECT_NO_THROW(ObjectState::from_row(fine));
}

TEST(GeometryGuard, DivergedMotionIsReportedWithFrameHandAndVertex) {
  const ArticulatedObject o = make_object("box", 1);
  const ObjectDistance distance(o);
  SequenceData d;
  d.name = "diverged";
  d.object_states = at::zeros({4, 7});
  d.hand_vertices = at::full({2, 4, 6, 3}, 0.3);
  d.hand_vertices[1][2][5][1].fill_(std::numeric_limits<float>::quiet_NaN());  // right hand, frame 2, vertex 5
  const std::string e = error_of([&] { evaluate_sequence(o, distance, d); });
  EXPECT_NE(e.find("sequence 'diverged', frame 2: right hand vertex 5 is (0.3, nan, 0.3): not finite"),
            std::string::npos)
      << e;
  d.hand_vertices[1][2][5][1].fill_(0.3);
  EXPECT_NO_THROW(evaluate_sequence(o, distance, d));
}

}  // namespace
}  // namespace bimart
