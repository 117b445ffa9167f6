#include "core/geometry/convex_hull.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <vector>

#include "core/util/error.h"

namespace bimart {

TriangleMesh convex_hull(const Points3& points) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  if (points.rows() < 4) throw Error("convex hull: needs at least 4 points, got " + std::to_string(points.rows()));
  std::vector<K::Point_3> in;
  in.reserve(static_cast<size_t>(points.rows()));
  for (Eigen::Index i = 0; i < points.rows(); ++i) in.emplace_back(points(i, 0), points(i, 1), points(i, 2));
  Mesh hull;
  CGAL::convex_hull_3(in.begin(), in.end(), hull);
  if (hull.number_of_faces() < 4) throw Error("convex hull: the points span no volume (they lie in a plane or on a line)");
  TriangleMesh m;
  m.vertices.resize(static_cast<Eigen::Index>(hull.number_of_vertices()), 3);
  std::vector<int> index(hull.num_vertices(), -1);
  int n = 0;
  for (Mesh::Vertex_index v : hull.vertices()) {
    const K::Point_3& p = hull.point(v);
    m.vertices.row(n) << p.x(), p.y(), p.z();
    index[v.idx()] = n++;
  }
  m.faces.resize(static_cast<Eigen::Index>(hull.number_of_faces()), 3);
  int f = 0;
  for (Mesh::Face_index face : hull.faces()) {
    int c = 0;
    for (Mesh::Vertex_index v : CGAL::vertices_around_face(hull.halfedge(face), hull)) m.faces(f, c++) = index[v.idx()];
    ++f;
  }
  return m;
}

}  // namespace bimart
