#include "core/object/families/primitives.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

namespace bimart::shapes {

namespace {

int cells(double length, double spacing, int at_least) {
  return std::max(at_least, static_cast<int>(std::lround(length / spacing)));
}

// Flips every face when the (closed) mesh encloses negative volume, so normals point out.
void orient_outward(TriangleMesh& m) {
  double v = 0;
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    v += a.dot(b.cross(c));
  }
  if (v < 0) m.faces.col(1).swap(m.faces.col(2));
}

TriangleMesh from_lists(const std::vector<Eigen::Vector3d>& verts, const std::vector<Eigen::Vector3i>& faces) {
  TriangleMesh m;
  m.vertices.resize(static_cast<Eigen::Index>(verts.size()), 3);
  for (std::size_t i = 0; i < verts.size(); ++i) m.vertices.row(static_cast<Eigen::Index>(i)) = verts[i];
  m.faces.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i) m.faces.row(static_cast<Eigen::Index>(i)) = faces[i];
  orient_outward(m);
  return m;
}

// Unit vectors (u, v, a) with u x v = a for coordinate axis a.
std::tuple<Eigen::Vector3d, Eigen::Vector3d, Eigen::Vector3d> frame(int axis) {
  const Eigen::Vector3d a = Eigen::Vector3d::Unit(axis);
  return {Eigen::Vector3d::Unit((axis + 1) % 3), Eigen::Vector3d::Unit((axis + 2) % 3), a};
}

// A surface of revolution of `profile` (radius, height) pairs that starts and ends on the
// axis (radius 0) with every point between off the axis: poles joined to rings by fans.
TriangleMesh lathe(const std::vector<std::pair<double, double>>& profile, const Eigen::Vector3d& center, int axis,
                   int segments) {
  const auto [u, v, a] = frame(axis);
  std::vector<Eigen::Vector3d> verts;
  std::vector<Eigen::Vector3i> faces;
  const int rings = static_cast<int>(profile.size()) - 2;
  verts.push_back(center + profile.front().second * a);
  for (int r = 0; r < rings; ++r) {
    const auto [rad, h] = profile[static_cast<std::size_t>(r + 1)];
    for (int k = 0; k < segments; ++k) {
      const double phi = 2 * M_PI * k / segments;
      verts.push_back(center + h * a + rad * (std::cos(phi) * u + std::sin(phi) * v));
    }
  }
  verts.push_back(center + profile.back().second * a);
  const int top = static_cast<int>(verts.size()) - 1;
  auto ring = [&](int r, int k) { return 1 + r * segments + (k % segments); };
  for (int k = 0; k < segments; ++k) {
    faces.emplace_back(0, ring(0, k + 1), ring(0, k));
    for (int r = 0; r + 1 < rings; ++r) {
      faces.emplace_back(ring(r, k), ring(r, k + 1), ring(r + 1, k + 1));
      faces.emplace_back(ring(r, k), ring(r + 1, k + 1), ring(r + 1, k));
    }
    faces.emplace_back(top, ring(rings - 1, k), ring(rings - 1, k + 1));
  }
  return from_lists(verts, faces);
}

// Lattice coordinates along one box side [-h, h]: finer bands of `n_round` cells over the
// rounded ends [-h, -h + r] and [h - r, h], uniform cells between.
std::vector<double> side_coordinates(double h, double r, double spacing) {
  std::vector<double> c;
  const int n_mid = cells(2 * (h - r), spacing, 1);
  const int n_round = r > 0 ? cells(M_PI * r / 2, spacing, 2) : 0;
  for (int i = 0; i < n_round; ++i) c.push_back(-h + r * i / n_round);
  for (int i = 0; i <= n_mid; ++i) c.push_back(-(h - r) + 2 * (h - r) * i / n_mid);
  for (int i = 1; i <= n_round; ++i) c.push_back((h - r) + r * i / n_round);
  return c;
}

}  // namespace

TriangleMesh rounded_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double radius, double spacing) {
  const Eigen::Vector3d half = 0.5 * (hi - lo), center = 0.5 * (hi + lo);
  const double r = std::clamp(radius, 0.0, 0.49 * half.minCoeff());
  std::array<std::vector<double>, 3> coord;
  std::array<int, 3> n{};
  for (int d = 0; d < 3; ++d) {
    coord[static_cast<std::size_t>(d)] = side_coordinates(half[d], r, spacing);
    n[static_cast<std::size_t>(d)] = static_cast<int>(coord[static_cast<std::size_t>(d)].size()) - 1;
  }
  // Surface points of the lattice, welded by their integer coordinates, then pushed onto
  // the rounded box: nearest point of the inner box plus r along the offset direction.
  std::map<std::array<int, 3>, int> index;
  std::vector<Eigen::Vector3d> verts;
  auto vertex = [&](std::array<int, 3> ijk) {
    auto [it, inserted] = index.try_emplace(ijk, static_cast<int>(verts.size()));
    if (inserted) {
      Eigen::Vector3d q;
      for (int d = 0; d < 3; ++d) q[d] = coord[static_cast<std::size_t>(d)][static_cast<std::size_t>(ijk[static_cast<std::size_t>(d)])];
      Eigen::Vector3d p = q;
      if (r > 0) {
        const Eigen::Vector3d inner = q.cwiseMax(-(half.array() - r).matrix()).cwiseMin((half.array() - r).matrix());
        p = inner + r * (q - inner).normalized();
      }
      verts.push_back(center + p);
    }
    return it->second;
  };
  std::vector<Eigen::Vector3i> faces;
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      for (int i = 0; i < n[static_cast<std::size_t>(u)]; ++i)
        for (int j = 0; j < n[static_cast<std::size_t>(v)]; ++j) {
          auto at = [&](int di, int dj) {
            std::array<int, 3> ijk{};
            ijk[static_cast<std::size_t>(a)] = side ? n[static_cast<std::size_t>(a)] : 0;
            ijk[static_cast<std::size_t>(u)] = i + di;
            ijk[static_cast<std::size_t>(v)] = j + dj;
            return vertex(ijk);
          };
          const int p00 = at(0, 0), p10 = at(1, 0), p11 = at(1, 1), p01 = at(0, 1);
          // Counter-clockwise seen from outside: (u, v, a) is right-handed.
          if (side) {
            faces.emplace_back(p00, p10, p11);
            faces.emplace_back(p00, p11, p01);
          } else {
            faces.emplace_back(p00, p11, p10);
            faces.emplace_back(p00, p01, p11);
          }
        }
    }
  }
  return from_lists(verts, faces);
}

TriangleMesh rounded_cylinder(const Eigen::Vector3d& center, int axis, double radius, double length,
                              double edge_radius, double spacing) {
  const double e = std::clamp(edge_radius, 0.0, std::min(radius, length / 2));
  const double flat = radius - e, side = length - 2 * e, h = length / 2;
  std::vector<std::pair<double, double>> p{{0.0, -h}};
  if (flat > 1e-12) {
    const int n = cells(flat, spacing, 1);
    for (int k = 1; k <= n; ++k) p.emplace_back(flat * k / n, -h);
  }
  const int n_arc = cells(M_PI * e / 2, spacing, 2);
  if (e > 0)
    for (int k = 1; k <= n_arc; ++k) {
      const double t = -M_PI / 2 + M_PI / 2 * k / n_arc;
      p.emplace_back(flat + e * std::cos(t), -h + e + e * std::sin(t));
    }
  if (side > 1e-12) {
    const int n = cells(side, spacing, 1);
    for (int k = 1; k <= n; ++k) p.emplace_back(radius, -h + e + side * k / n);
  }
  if (e > 0)
    for (int k = 1; k <= n_arc; ++k) {
      const double t = M_PI / 2 * k / n_arc;
      p.emplace_back(flat + e * std::cos(t), h - e + e * std::sin(t));
    }
  if (flat > 1e-12) {
    const int n = cells(flat, spacing, 1);
    for (int k = 1; k <= n; ++k) p.emplace_back(flat * (n - k) / n, h);
  }
  p.back().first = 0.0;  // the top pole (exactly on the axis also when flat == 0)
  const int segments = cells(2 * M_PI * radius, spacing, 12);
  return lathe(p, center, axis, segments);
}

TriangleMesh capsule(const Eigen::Vector3d& center, int axis, double radius, double length, double spacing) {
  return rounded_cylinder(center, axis, radius, std::max(length, 2 * radius), radius, spacing);
}

TriangleMesh torus(const Eigen::Vector3d& center, int axis, double major, double minor, double spacing) {
  const auto [u, v, a] = frame(axis);
  const int nu = cells(2 * M_PI * major, spacing, 16), nv = cells(2 * M_PI * minor, spacing, 8);
  std::vector<Eigen::Vector3d> verts;
  std::vector<Eigen::Vector3i> faces;
  for (int i = 0; i < nu; ++i) {
    const double phi = 2 * M_PI * i / nu;
    const Eigen::Vector3d radial = std::cos(phi) * u + std::sin(phi) * v;
    for (int j = 0; j < nv; ++j) {
      const double t = 2 * M_PI * j / nv;
      verts.push_back(center + (major + minor * std::cos(t)) * radial + minor * std::sin(t) * a);
    }
  }
  auto id = [&](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return from_lists(verts, faces);
}

void append(TriangleMesh& to, const TriangleMesh& m) {
  const Eigen::Index nv = to.num_vertices(), nf = to.num_faces();
  to.vertices.conservativeResize(nv + m.num_vertices(), 3);
  to.vertices.bottomRows(m.num_vertices()) = m.vertices;
  to.faces.conservativeResize(nf + m.num_faces(), 3);
  to.faces.bottomRows(m.num_faces()) = m.faces.array() + static_cast<int>(nv);
}

TriangleMesh transformed(const TriangleMesh& m, const Eigen::Isometry3d& T) {
  TriangleMesh out = m;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    out.vertices.row(i) = (T * Eigen::Vector3d(m.vertices.row(i))).transpose();
  return out;
}

}  // namespace bimart::shapes
