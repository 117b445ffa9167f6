#include "core/hand/procedural_hand_mesh.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/tangential_relaxation.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_filter.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/boost/graph/helpers.h>

#include <array>
#include <cmath>
#include <string>
#include <unordered_map>

#include <Eigen/Geometry>
#include <vector>

#include "core/util/error.h"

namespace bimart {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMS = CGAL::Surface_mesh_simplification;

TriangleMesh to_triangle_mesh(const Mesh& m) {
  TriangleMesh out;
  out.vertices.resize(static_cast<Eigen::Index>(m.number_of_vertices()), 3);
  for (auto v : m.vertices()) {
    const Point& p = m.point(v);
    out.vertices.row(v.idx()) << p.x(), p.y(), p.z();
  }
  out.faces.resize(static_cast<Eigen::Index>(m.number_of_faces()), 3);
  Eigen::Index f = 0;
  for (auto face : m.faces()) {
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(face), m)) out.faces(f, k++) = static_cast<int>(v.idx());
    ++f;
  }
  return out;
}

// False when some face cannot be added (non-manifold or bad indices).
bool to_cgal_mesh(const TriangleMesh& in, Mesh& m) {
  std::vector<Mesh::Vertex_index> vs;
  for (Eigen::Index i = 0; i < in.num_vertices(); ++i)
    vs.push_back(m.add_vertex(Point(in.vertices(i, 0), in.vertices(i, 1), in.vertices(i, 2))));
  for (Eigen::Index f = 0; f < in.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k)
      if (in.faces(f, k) < 0 || in.faces(f, k) >= in.num_vertices()) return false;
    if (m.add_face(vs[in.faces(f, 0)], vs[in.faces(f, 1)], vs[in.faces(f, 2)]) == Mesh::null_face()) return false;
  }
  return true;
}

// Newton steps along the gradient onto the zero level set.
Eigen::Vector3d project(const std::function<double(const Eigen::Vector3d&)>& sdf, Eigen::Vector3d p) {
  constexpr double h = 1e-6;
  for (int it = 0; it < 5; ++it) {
    const double f = sdf(p);
    if (std::abs(f) < 1e-7) break;
    Eigen::Vector3d g;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d q = p;
      q[k] += h;
      g[k] = (sdf(q) - f) / h;
    }
    const double g2 = g.squaredNorm();
    if (g2 < 1e-12) break;
    p -= f * g / g2;
  }
  return p;
}


// Marching tetrahedra on a regular grid, each cube split into the 6 tetrahedra around its
// main diagonal (a conforming split), vertices shared through the grid edge they lie on.
// Hand-written: CGAL 5.5 has no isosurface extractor (Isosurfacing_3 came in 6.0), and its
// Surface_mesher's output depends on memory addresses, so it is not reproducible.
Mesh marching_tetrahedra(const std::function<double(const Eigen::Vector3d&)>& sdf, const Eigen::Vector3d& lo,
                         const Eigen::Vector3d& hi, double step) {
  const Eigen::Array3i n = (((hi - lo) / step).array().ceil()).cast<int>() + 1;
  auto id = [&](int i, int j, int k) { return (static_cast<long>(k) * n.y() + j) * n.x() + i; };
  std::vector<double> f(static_cast<std::size_t>(n.prod()));
  auto point = [&](long g) {
    const long i = g % n.x(), j = (g / n.x()) % n.y(), k = g / (static_cast<long>(n.x()) * n.y());
    return Eigen::Vector3d(lo + step * Eigen::Vector3d(i, j, k));
  };
  for (long g = 0; g < static_cast<long>(f.size()); ++g) {
    const double v = sdf(point(g));
    f[g] = v == 0 ? 1e-12 : v;  // no grid point exactly on the surface
  }
  Mesh m;
  std::unordered_map<long, Mesh::Vertex_index> on_edge;  // key: a * size + b, a < b
  auto vertex = [&](long a, long b) {
    if (a > b) std::swap(a, b);
    const long key = a * static_cast<long>(f.size()) + b;
    const auto it = on_edge.find(key);
    if (it != on_edge.end()) return it->second;
    const double t = f[a] / (f[a] - f[b]);
    const Eigen::Vector3d p = point(a) + t * (point(b) - point(a));
    return on_edge[key] = m.add_vertex(Point(p.x(), p.y(), p.z()));
  };
  auto add = [&](Mesh::Vertex_index a, Mesh::Vertex_index b, Mesh::Vertex_index c, const Eigen::Vector3d& out) {
    const Point &pa = m.point(a), &pb = m.point(b), &pc = m.point(c);
    const Eigen::Vector3d ea(pb.x() - pa.x(), pb.y() - pa.y(), pb.z() - pa.z());
    const Eigen::Vector3d eb(pc.x() - pa.x(), pc.y() - pa.y(), pc.z() - pa.z());
    if (ea.cross(eb).dot(out) < 0) std::swap(b, c);
    if (m.add_face(a, b, c) == Mesh::null_face())
      throw Error("mesh_implicit_surface: marching tetrahedra produced a non-manifold face");
  };
  static constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  for (int k = 0; k + 1 < n.z(); ++k)
    for (int j = 0; j + 1 < n.y(); ++j)
      for (int i = 0; i + 1 < n.x(); ++i) {
        long corner[8];
        for (int c = 0; c < 8; ++c) corner[c] = id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
        for (const auto& tet : kTets) {
          std::vector<long> in, out;
          for (int c : tet) (f[corner[c]] < 0 ? in : out).push_back(corner[c]);
          if (in.empty() || out.empty()) continue;
          Eigen::Vector3d dir = Eigen::Vector3d::Zero();  // from the inside corners to the outside ones
          for (long g : out) dir += point(g) / static_cast<double>(out.size());
          for (long g : in) dir -= point(g) / static_cast<double>(in.size());
          if (in.size() == 1 || out.size() == 1) {
            const std::vector<long>& one = in.size() == 1 ? in : out;
            const std::vector<long>& three = in.size() == 1 ? out : in;
            add(vertex(one[0], three[0]), vertex(one[0], three[1]), vertex(one[0], three[2]), dir);
          } else {  // a quad: in0-out0, in0-out1, in1-out1, in1-out0
            const auto a = vertex(in[0], out[0]), b = vertex(in[0], out[1]), c = vertex(in[1], out[1]),
                       d = vertex(in[1], out[0]);
            add(a, b, c, dir);
            add(a, c, d, dir);
          }
        }
      }
  return m;
}

}  // namespace

TriangleMesh mesh_implicit_surface(const std::function<double(const Eigen::Vector3d&)>& sdf,
                                   const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                   const ImplicitMeshOptions& options) {
  if (!(sdf(lo) > 0 && sdf(hi) > 0)) throw Error("mesh_implicit_surface: the box corners must lie outside the surface");
  Mesh m = marching_tetrahedra(sdf, lo, hi, options.grid_step);
  if (m.is_empty() || !CGAL::is_closed(m)) {
    for (auto h : m.halfedges())
      if (m.is_border(h)) {
        const Point& p = m.point(m.target(h));
        throw Error("mesh_implicit_surface: the dense mesh is not closed near (" + std::to_string(p.x()) + ", " +
                    std::to_string(p.y()) + ", " + std::to_string(p.z()) + "); does the surface leave the box?");
      }
    throw Error("mesh_implicit_surface: the dense mesh is empty");
  }
  if (static_cast<int>(m.number_of_vertices()) < options.target_vertices)
    throw Error("mesh_implicit_surface: the dense mesh has only " + std::to_string(m.number_of_vertices()) +
                " vertices, fewer than the target; lower grid_step");

  // Marching tetrahedra leaves slivers; even the triangles out first (and back onto the
  // surface), so that the simplification starts from a regular mesh.
  PMP::isotropic_remeshing(faces(m), 1.5 * options.grid_step, m, CGAL::parameters::number_of_iterations(3));
  m.collect_garbage();
  for (auto v : m.vertices()) {
    const Point& p = m.point(v);
    const Eigen::Vector3d q = project(sdf, Eigen::Vector3d(p.x(), p.y(), p.z()));
    m.point(v) = Point(q.x(), q.y(), q.z());
  }

  // Closed genus-0 triangle mesh: E = 3 (V - 2). Each collapse removes one vertex.
  const std::size_t target_edges = 3 * (static_cast<std::size_t>(options.target_vertices) - 2);
  SMS::Count_stop_predicate<Mesh> stop(target_edges);
  SMS::edge_collapse(m, stop, CGAL::parameters::filter(SMS::Bounded_normal_change_filter<>()));
  m.collect_garbage();

  for (int it = 0; it < options.relax_iterations; ++it) {
    PMP::tangential_relaxation(m, CGAL::parameters::number_of_iterations(1));
    for (auto v : m.vertices()) {
      const Point& p = m.point(v);
      const Eigen::Vector3d q = project(sdf, Eigen::Vector3d(p.x(), p.y(), p.z()));
      m.point(v) = Point(q.x(), q.y(), q.z());
    }
  }

  if (!PMP::is_outward_oriented(m)) PMP::reverse_face_orientations(m);
  if (!CGAL::is_closed(m)) throw Error("mesh_implicit_surface: the simplified mesh is not closed");
  if (PMP::does_self_intersect(m))
    throw Error("mesh_implicit_surface: the simplified mesh intersects itself; raise target_vertices");
  return to_triangle_mesh(m);
}

SurfaceCheck check_surface(const TriangleMesh& mesh) {
  SurfaceCheck c;
  Mesh m;
  c.manifold = to_cgal_mesh(mesh, m);
  if (!c.manifold) return c;
  c.closed = CGAL::is_closed(m);
  c.self_intersecting = PMP::does_self_intersect(m);
  c.outward = c.closed && PMP::is_outward_oriented(m);
  return c;
}

}  // namespace bimart
