// The CGAL inside test against an independent brute-force ray-parity test: 10,000 random
// points per procedural category, both parts, 0 disagreements away from the surface.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "core/geometry/mesh_distance.h"
#include "core/object/families/families.h"

namespace bimart {
namespace {

// Möller–Trumbore: does the ray o + t d (t > 0) cross the triangle? `grazing` is set when
// the hit is within eps of an edge (the parity is then unreliable).
bool ray_hits(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a,
              const Eigen::Vector3d& b, const Eigen::Vector3d& c, bool& grazing) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-18) return false;
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = o - a;
  const double u = s.dot(p) * inv;
  if (u < -1e-9 || u > 1 + 1e-9) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < -1e-9 || u + v > 1 + 1e-9) return false;
  const double t = e2.dot(q) * inv;
  if (t <= 0) return false;
  if (u < 1e-9 || v < 1e-9 || u + v > 1 - 1e-9) grazing = true;
  return true;
}

// Inside = odd crossings for some component (components by shared vertices, as a part is
// a union of closed primitives). Re-casts in another random direction on a grazing hit.
class ParityInside {
 public:
  explicit ParityInside(const TriangleMesh& m) : m_(m) {
    std::vector<int> parent(static_cast<size_t>(m.num_vertices()));
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
      parent[find(m.faces(f, 1))] = find(m.faces(f, 0));
      parent[find(m.faces(f, 2))] = find(m.faces(f, 0));
    }
    std::vector<int> id(parent.size(), -1);
    for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
      const int r = find(m.faces(f, 0));
      if (id[r] < 0) id[r] = num_components_++;
      component_.push_back(id[r]);
    }
  }

  bool inside(const Eigen::Vector3d& p, std::mt19937_64& rng) const {
    std::normal_distribution<double> n;
    for (int attempt = 0; attempt < 20; ++attempt) {
      const Eigen::Vector3d d = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
      std::vector<int> hits(static_cast<size_t>(num_components_), 0);
      bool grazing = false;
      for (Eigen::Index f = 0; f < m_.num_faces(); ++f)
        if (ray_hits(p, d, m_.vertices.row(m_.faces(f, 0)), m_.vertices.row(m_.faces(f, 1)),
                     m_.vertices.row(m_.faces(f, 2)), grazing))
          ++hits[static_cast<size_t>(component_[static_cast<size_t>(f)])];
      if (grazing) continue;
      for (int h : hits)
        if (h % 2) return true;
      return false;
    }
    ADD_FAILURE() << "every ray grazed an edge";
    return false;
  }

 private:
  const TriangleMesh& m_;
  std::vector<int> component_;
  int num_components_ = 0;
};

TEST(InsideTest, AgreesWithBruteForceRayParityOnEveryCategory) {
  const int kPoints = 10000;
  for (const std::string& category : object_categories()) {
    const ArticulatedObject object = make_object(category, 11);
    std::mt19937_64 rng(1234);
    int tested = 0, disagreements = 0, inside_count = 0;
    for (const TriangleMesh* part : {&object.top, &object.bottom}) {
      const MeshDistance md(*part);
      const ParityInside brute(*part);
      const Eigen::Vector3d lo = part->vertices.colwise().minCoeff().transpose();
      const Eigen::Vector3d hi = part->vertices.colwise().maxCoeff().transpose();
      const Eigen::Vector3d margin = 0.1 * (hi - lo);
      std::uniform_real_distribution<double> u(0, 1);
      for (int i = 0; i < kPoints / 2; ++i) {
        const Eigen::Vector3d t(u(rng), u(rng), u(rng));
        const Eigen::Vector3d p = lo - margin + t.cwiseProduct(hi - lo + 2 * margin);
        const double sd = md.signed_distance(p);
        if (std::abs(sd) < 1e-6) continue;  // on the surface: either answer is right
        ++tested;
        const bool in = brute.inside(p, rng);
        inside_count += in;
        if (in != (sd > 0) || in != md.inside(p)) ++disagreements;
      }
    }
    EXPECT_EQ(disagreements, 0) << category;
    EXPECT_GT(tested, kPoints * 99 / 100) << category;
    EXPECT_GT(inside_count, 100) << category;  // the sample reaches inside
  }
}

}  // namespace
}  // namespace bimart
