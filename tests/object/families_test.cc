#include "core/object/families/families.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "core/object/families/primitives.h"
#include "core/object/mesh_repair.h"
#include "core/object/object_state.h"
#include "core/util/error.h"

namespace bimart {
namespace {

TEST(Primitives, VolumesMatchTheShapes) {
  const double s = 0.004;
  const TriangleMesh box = shapes::rounded_box({-0.1, -0.05, -0.02}, {0.1, 0.05, 0.02}, 0.0, s);
  EXPECT_TRUE(is_closed_mesh(box));
  EXPECT_NEAR(signed_volume(box), 0.2 * 0.1 * 0.04, 1e-15);
  // Rounded box of full sides a, b, c: the box minus what rounding removes along the 12
  // edges, (4 - pi) r^2 per unit of straight edge length, and at the 8 corners, 8 r^3 - 4/3 pi r^3.
  const double a = 0.2, b = 0.1, c = 0.04, r = 0.01;
  const TriangleMesh rbox = shapes::rounded_box({-a / 2, -b / 2, -c / 2}, {a / 2, b / 2, c / 2}, r, 0.002);
  const double v_rbox = a * b * c - (4 - M_PI) * r * r * ((a - 2 * r) + (b - 2 * r) + (c - 2 * r)) -
                        (8 - 4 * M_PI / 3) * r * r * r;
  EXPECT_TRUE(is_closed_mesh(rbox));
  EXPECT_NEAR(signed_volume(rbox), v_rbox, 0.01 * v_rbox);
  const TriangleMesh cyl = shapes::rounded_cylinder({0.1, 0.2, 0.3}, 1, 0.03, 0.1, 0.0, s);
  EXPECT_TRUE(is_closed_mesh(cyl));
  EXPECT_NEAR(signed_volume(cyl), M_PI * 0.03 * 0.03 * 0.1, 0.01 * M_PI * 0.03 * 0.03 * 0.1);
  const TriangleMesh cap = shapes::capsule({0, 0, 0}, 0, 0.02, 0.1, s);
  const double v_cap = M_PI * 0.02 * 0.02 * 0.06 + 4.0 / 3.0 * M_PI * std::pow(0.02, 3);
  EXPECT_TRUE(is_closed_mesh(cap));
  EXPECT_NEAR(signed_volume(cap), v_cap, 0.02 * v_cap);
  EXPECT_NEAR(cap.vertices.col(0).maxCoeff(), 0.05, 1e-15);
  const TriangleMesh tor = shapes::torus({0, 0, 0}, 2, 0.03, 0.005, 0.002);
  const double v_tor = 2 * M_PI * M_PI * 0.03 * 0.005 * 0.005;
  EXPECT_TRUE(is_closed_mesh(tor));
  EXPECT_NEAR(signed_volume(tor), v_tor, 0.03 * v_tor);
}

TEST(Families, AtLeastTenCategoriesWithSensibleTables) {
  const auto names = object_categories();
  EXPECT_GE(names.size(), 10u);
  for (const auto& f : object_families()) {
    EXPECT_GE(f.angle_min, 0.0) << f.name;
    EXPECT_GT(f.angle_max, f.angle_min + 0.5) << f.name;  // opens by at least ~30 degrees
    EXPECT_LE(f.angle_max, M_PI) << f.name;
    EXPECT_GT(f.open_angle, f.angle_min) << f.name;
    EXPECT_LE(f.open_angle, f.angle_max) << f.name;
    for (const auto& d : f.dimensions) {
      EXPECT_GT(d.min, 0) << f.name << "." << d.name;
      EXPECT_LT(d.min, d.max) << f.name << "." << d.name;
      EXPECT_LT(d.max, 1.0) << f.name << "." << d.name;
    }
  }
}

TEST(Families, EveryCategoryIsClosedSensibleAndSeeded) {
  for (const std::string& name : object_categories()) {
    const ObjectFamily& f = object_family(name);
    std::vector<Dimensions> dims;
    for (std::uint64_t seed : {0, 1, 2}) {
      const ArticulatedObject o = make_object(name, seed);
      const std::string what = o.name;
      EXPECT_EQ(o.category, name);
      EXPECT_TRUE(is_closed_mesh(o.top)) << what;
      EXPECT_TRUE(is_closed_mesh(o.bottom)) << what;
      EXPECT_GT(signed_volume(o.top), 0) << what;
      EXPECT_GT(signed_volume(o.bottom), 0) << what;
      validate_mesh(o.top, what + " top");  // no degenerate faces, finite
      validate_mesh(o.bottom, what + " bottom");
      const Eigen::Index n = o.top.num_vertices() + o.bottom.num_vertices();
      EXPECT_GE(n, 300) << what;
      EXPECT_LE(n, 4000) << what;
      std::cout << what << ": " << o.top.num_vertices() << " + " << o.bottom.num_vertices() << "\n";
      EXPECT_GE(o.top.num_vertices(), 100) << what;
      EXPECT_GE(bounding_radius(o.top), 0.01) << what;
      EXPECT_LE(bounding_radius(o.bottom), 3.0) << what;
      EXPECT_EQ(o.angle_min, f.angle_min);
      EXPECT_EQ(o.angle_max, f.angle_max);
      const double s_o = object_scale(o);
      EXPECT_GT(s_o, 0.85 / 1.0) << what;   // every object fits in a 1 m ball
      EXPECT_LT(s_o, 0.85 / 0.05) << what;  // and none is smaller than 5 cm
      // Closed, the top part extends towards -x from the hinge, so a positive angle lifts it
      // (+y); the bottom part is below the plane y = 0 (families.h; the microwave stands
      // along z, scissors lie in z = 0 with blades along +x).
      if (name != "scissors") {
        const double cx = o.top.vertices.col(0).mean();
        EXPECT_LT(cx, 0) << what;
        const double lift = pose_canonical(o, 0.1).top.col(1).mean() - o.top.vertices.col(1).mean();
        EXPECT_NEAR(lift, -cx * std::sin(0.1) - o.top.vertices.col(1).mean() * (1 - std::cos(0.1)), 1e-12) << what;
        EXPECT_GT(lift, 0) << what;
      }
      if (name != "microwave" && name != "scissors") EXPECT_LE(o.bottom.vertices.col(1).maxCoeff(), 1e-9) << what;
      // Same seed: identical meshes.
      const ArticulatedObject again = make_object(name, seed);
      EXPECT_EQ(again.top.vertices, o.top.vertices) << what;
      EXPECT_EQ(again.bottom.faces, o.bottom.faces) << what;
      dims.push_back(sample_dimensions(f, seed));
      for (const auto& r : f.dimensions) {
        EXPECT_GE(dims.back()[r.name], r.min);
        EXPECT_LT(dims.back()[r.name], r.max);
      }
    }
    // Different seeds: different dimensions (every one of them).
    for (const auto& r : f.dimensions) {
      EXPECT_NE(dims[0][r.name], dims[1][r.name]) << name << "." << r.name;
      EXPECT_NE(dims[1][r.name], dims[2][r.name]) << name << "." << r.name;
    }
    EXPECT_NE(make_object(name, 0).bottom.vertices.col(0).minCoeff(),
              make_object(name, 1).bottom.vertices.col(0).minCoeff())
        << name;
  }
}

TEST(Families, VertexCountsStayInRangeAtTheExtremesOfTheTable) {
  for (const auto& f : object_families()) {
    Dimensions lo, hi;
    for (const auto& r : f.dimensions) {
      lo[r.name] = r.min;
      hi[r.name] = r.max;
    }
    for (const Dimensions* d : {&lo, &hi}) {
      const ArticulatedObject o = make_object(f.name, *d, f.name);
      const Eigen::Index n = o.top.num_vertices() + o.bottom.num_vertices();
      EXPECT_GE(n, 300) << f.name << (d == &lo ? " smallest" : " largest");
      EXPECT_LE(n, 4000) << f.name << (d == &lo ? " smallest" : " largest");
      EXPECT_TRUE(is_closed_mesh(o.top) && is_closed_mesh(o.bottom)) << f.name;
      std::cout << f.name << (d == &lo ? " smallest: " : " largest: ") << n << "\n";
    }
  }
}

TEST(Families, SeedStreamIsFixed) {
  // std::mt19937_64's output is fixed by the standard and the mapping to [0, 1) is ours
  // (top 53 bits), so a seed's dimensions do not depend on the standard library.
  const ObjectFamily& f = object_family("phone");
  const Dimensions a = sample_dimensions(f, 42), b = sample_dimensions(f, 42);
  EXPECT_EQ(a, b);
  std::mt19937_64 rng(42);
  const double u = static_cast<double>(rng() >> 11) / 9007199254740992.0;
  EXPECT_EQ(a.at(f.dimensions[0].name), f.dimensions[0].min + (f.dimensions[0].max - f.dimensions[0].min) * u);
}

TEST(Families, UnknownCategorySuggestsTheClosest) {
  try {
    make_object("labtop", 1);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'laptop'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bimart
