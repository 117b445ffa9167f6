#include "core/geometry/mesh_distance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "core/util/error.h"

namespace bimart {
namespace {

// A closed cylinder about z from z = 0 to z = h: n side quads, fan caps.
TriangleMesh make_cylinder(double r, double h, int n) {
  TriangleMesh m;
  m.vertices.resize(2 * n + 2, 3);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    m.vertices.row(i) << r * std::cos(a), r * std::sin(a), 0;
    m.vertices.row(n + i) << r * std::cos(a), r * std::sin(a), h;
  }
  m.vertices.row(2 * n) << 0, 0, 0;
  m.vertices.row(2 * n + 1) << 0, 0, h;
  m.faces.resize(4 * n, 3);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.faces.row(4 * i + 0) << i, j, n + j;
    m.faces.row(4 * i + 1) << i, n + j, n + i;
    m.faces.row(4 * i + 2) << 2 * n, j, i;              // bottom, facing -z
    m.faces.row(4 * i + 3) << 2 * n + 1, n + i, n + j;  // top, facing +z
  }
  return m;
}

TEST(MeshDistance, UnitCubeKnownDepths) {
  const MeshDistance d(make_box({0, 0, 0}, {1, 1, 1}));
  struct Case { Eigen::Vector3d p; double sd; };
  const std::vector<Case> cases = {
      {{0.5, 0.5, 0.5}, 0.5},       {{0.5, 0.5, 0.9}, 0.1},     {{0.5, 0.5, 0.99}, 0.01},
      {{0.5, 0.5, 0.995}, 0.005},   {{0.2, 0.5, 0.5}, 0.2},     {{0.5, 0.5, 1.01}, -0.01},
      {{0.5, 0.5, 1.005}, -0.005},  {{0.5, 0.5, 1.3}, -0.3},    {{-0.25, 0.5, 0.5}, -0.25},
      {{2, 2, 2}, -std::sqrt(3.0)}, {{1.3, 1.4, 0.5}, -0.5},    {{0.5, 0.5, 1e-3}, 1e-3},
  };
  for (const Case& c : cases) {
    EXPECT_NEAR(d.signed_distance(c.p), c.sd, 1e-6) << c.p.transpose();
    const SurfaceQuery q = d.query(c.p);
    EXPECT_NEAR(q.signed_distance, c.sd, 1e-6) << c.p.transpose();
    EXPECT_NEAR((q.closest - c.p).norm(), std::abs(c.sd), 1e-6);
    EXPECT_GE(q.face, 0);
    EXPECT_LT(q.face, 12);
    EXPECT_EQ(d.inside(c.p), c.sd > 0);
  }
  EXPECT_EQ(d.num_components(), 1);
}

TEST(MeshDistance, NormalsPointOutOfTheMeshInsideOutsideAndOnTheSurface) {
  TriangleMesh box = make_box({0, 0, 0}, {1, 1, 1});
  TriangleMesh flipped = box;  // inward winding: the probe must still orient it outwards
  flipped.faces.col(1).swap(flipped.faces.col(2));
  for (const TriangleMesh* m : {&box, &flipped}) {
    const MeshDistance d(*m);
    for (const Eigen::Vector3d p : {Eigen::Vector3d(0.5, 0.4, 1.2), Eigen::Vector3d(0.5, 0.4, 0.9),
                                    Eigen::Vector3d(0.5, 0.4, 1.0)}) {
      const SurfaceQuery q = d.query(p);
      EXPECT_NEAR(q.normal.z(), 1.0, 1e-12) << p.transpose();
      EXPECT_NEAR(q.normal.head<2>().norm(), 0.0, 1e-12);
    }
    EXPECT_NEAR(d.query({-0.3, 0.5, 0.5}).normal.x(), -1.0, 1e-12);
  }
}

TEST(MeshDistance, CylinderKnownDepths) {
  const int n = 64;
  const double r = 0.05, h = 0.1;
  const double apothem = r * std::cos(M_PI / n);  // distance from the axis to a side facet
  const MeshDistance d(make_cylinder(r, h, n));
  const Eigen::Vector3d mid_dir(std::cos(M_PI / n), std::sin(M_PI / n), 0);  // a facet's middle
  for (double rho : {0.0, 0.01, 0.03, 0.045, 0.049, 0.051, 0.06, 0.1}) {
    const Eigen::Vector3d p = rho * mid_dir + Eigen::Vector3d(0, 0, h / 2);
    const double expected = apothem - rho;  // the side is nearer than the caps (h/2 = 0.05)
    EXPECT_NEAR(d.signed_distance(p), expected, 1e-6) << "rho " << rho;
  }
  // Along the axis: the caps.
  for (double z : {0.002, 0.005, 0.01, 0.02, -0.005, -0.01, 0.105, 0.2}) {
    const Eigen::Vector3d p(0, 0, z);
    const double expected = z < 0 ? z : (z > h ? h - z : std::min(z, h - z));
    EXPECT_NEAR(d.signed_distance(p), expected, 1e-6) << "z " << z;
  }
}

TEST(MeshDistance, ThresholdsAtExactlyOneCentimetreAndFiveMillimetres) {
  // Depths exactly representable relative to the face at z = 1: the metric thresholds are
  // strict (DESIGN §6: "more than 1 cm inside"), so these sit on them.
  const MeshDistance d(make_box({0, 0, 0}, {1, 1, 1}));
  EXPECT_NEAR(d.signed_distance({0.5, 0.5, 0.99}), 0.01, 1e-12);
  EXPECT_NEAR(d.signed_distance({0.5, 0.5, 1.005}), -0.005, 1e-12);
}

TEST(MeshDistance, OverlappingComponentsAreAUnion) {
  TriangleMesh m = make_box({0, 0, 0}, {1, 1, 1});
  const TriangleMesh b = make_box({0.5, 0, 0}, {1.5, 1, 1});
  const Eigen::Index nv = m.num_vertices(), nf = m.num_faces();
  m.vertices.conservativeResize(nv + b.num_vertices(), 3);
  m.vertices.bottomRows(b.num_vertices()) = b.vertices;
  m.faces.conservativeResize(nf + b.num_faces(), 3);
  m.faces.bottomRows(b.num_faces()) = b.faces.array() + static_cast<int>(nv);
  const MeshDistance d(m);
  EXPECT_EQ(d.num_components(), 2);
  // In the overlap (inside both): whole-mesh parity would say outside.
  EXPECT_TRUE(d.inside({0.75, 0.5, 0.5}));
  // Depth: the deeper of the two boxes (0.25 each), a lower bound of the union's 0.5.
  EXPECT_NEAR(d.signed_distance({0.75, 0.5, 0.5}), 0.25, 1e-9);
  EXPECT_NEAR(d.signed_distance({0.75, 0.5, 1.2}), -0.2, 1e-9);
  EXPECT_NEAR(d.signed_distance({1.7, 0.5, 0.5}), -0.2, 1e-9);
}

TEST(MeshDistance, RefusesOpenAndEmptyMeshes) {
  TriangleMesh open = make_box({0, 0, 0}, {1, 1, 1});
  open.faces.conservativeResize(10, 3);
  EXPECT_THROW(MeshDistance{open}, Error);
  EXPECT_THROW(MeshDistance{TriangleMesh{}}, Error);
  TriangleMesh bad = make_box({0, 0, 0}, {1, 1, 1});
  bad.faces(0, 0) = 99;
  EXPECT_THROW(MeshDistance{bad}, Error);
}

TEST(MeshDistance, ParallelQueriesMatchSerial) {
  MeshDistance d(make_cylinder(0.05, 0.1, 48));
  Points3 pts = Points3::Random(4000, 3) * 0.12;
  const Eigen::VectorXd serial = d.signed_distances(pts);
  std::vector<Eigen::VectorXd> par(2);
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t) threads.emplace_back([&, t] { par[t] = d.signed_distances(pts); });
  for (auto& th : threads) th.join();
  for (int t = 0; t < 2; ++t) EXPECT_EQ((par[t] - serial).cwiseAbs().maxCoeff(), 0.0);
  MeshDistance moved = std::move(d);
  EXPECT_EQ((moved.signed_distances(pts) - serial).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace bimart
