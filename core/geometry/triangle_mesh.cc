#include "core/geometry/triangle_mesh.h"

#include <Eigen/Geometry>

namespace bimart {

TriangleMesh make_box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  TriangleMesh m;
  m.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    m.vertices.row(i) << (i & 1 ? hi.x() : lo.x()), (i & 2 ? hi.y() : lo.y()),
        (i & 4 ? hi.z() : lo.z());
  m.faces.resize(12, 3);
  m.faces << 0, 2, 1, 1, 2, 3,  // z = lo
      4, 5, 6, 5, 7, 6,         // z = hi
      0, 1, 4, 1, 5, 4,         // y = lo
      2, 6, 3, 3, 6, 7,         // y = hi
      0, 4, 2, 2, 4, 6,         // x = lo
      1, 3, 5, 3, 7, 5;         // x = hi
  return m;
}

// The cross product's length is twice the triangle area: summing it weights by area.
Eigen::MatrixX3d vertex_normals(const TriangleMesh& m) {
  Eigen::MatrixX3d n = Eigen::MatrixX3d::Zero(m.num_vertices(), 3);
  for (Eigen::Index f = 0; f < m.num_faces(); ++f) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(f, 0)), b = m.vertices.row(m.faces(f, 1)),
                          c = m.vertices.row(m.faces(f, 2));
    const Eigen::RowVector3d fn = (b - a).cross(c - a).transpose();
    for (int k = 0; k < 3; ++k) n.row(m.faces(f, k)) += fn;
  }
  for (Eigen::Index v = 0; v < n.rows(); ++v) {
    const double len = n.row(v).norm();
    if (len > 0) n.row(v) /= len;
  }
  return n;
}

}  // namespace bimart
