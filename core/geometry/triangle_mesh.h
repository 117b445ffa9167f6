// A triangle mesh: vertex positions (metres) and faces (vertex indices, counter-clockwise
// seen from outside, so normals point outwards).
#pragma once

#include <Eigen/Core>

namespace bimart {

// [M, 3] points, one per row (metres).
using Points3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct TriangleMesh {
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> vertices;
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> faces;

  Eigen::Index num_vertices() const { return vertices.rows(); }
  Eigen::Index num_faces() const { return faces.rows(); }
};

// An axis-aligned box [min, max] as a closed mesh of 8 vertices and 12 outward faces.
TriangleMesh make_box(const Eigen::Vector3d& min, const Eigen::Vector3d& max);

// Unit area-weighted vertex normals [V, 3] (outwards for outward faces; zero for unused vertices).
Eigen::MatrixX3d vertex_normals(const TriangleMesh& mesh);

}  // namespace bimart
