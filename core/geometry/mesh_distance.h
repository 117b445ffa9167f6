// Signed distance to one closed triangle mesh (CGAL AABB tree, built once): closest point
// for the distance, a robust inside test for the sign. Positive inside, negative outside
// (DESIGN §6). Queries are in the mesh's own frame; callers move the points, not the mesh.
// A mesh may hold several closed components that overlap: inside = inside any of them.
#pragma once

#include <memory>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

struct SurfaceQuery {
  double signed_distance = 0;  // metres; > 0 inside
  Eigen::Vector3d closest = Eigen::Vector3d::Zero();  // nearest surface point, mesh frame
  int face = -1;                                      // face of the nearest point
  // Unit outward normal there: along p − closest (towards p outside, away inside); from
  // the nearest face, oriented by an inside probe, for a point on the surface.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

class MeshDistance {
 public:
  // Throws bimart::Error when the mesh is empty or not closed (inside tests need closed meshes).
  explicit MeshDistance(const TriangleMesh& mesh);
  ~MeshDistance();
  MeshDistance(MeshDistance&&) noexcept;
  MeshDistance& operator=(MeshDistance&&) noexcept;

  SurfaceQuery query(const Eigen::Vector3d& p) const;
  double signed_distance(const Eigen::Vector3d& p) const;
  bool inside(const Eigen::Vector3d& p) const;
  // Row-wise signed distances of [M, 3] points; thread-safe (const queries).
  Eigen::VectorXd signed_distances(const Points3& points) const;
  // Closed components (by shared vertices). A part may be a union of overlapping closed
  // components; "inside" means inside any of them (ray parity runs per component).
  int num_components() const;
  // The axis-aligned bounding box of the mesh's vertices.
  Eigen::AlignedBox3d bounding_box() const;
  // max over the rows of signed_distances(points), without computing every distance: rows
  // that cannot beat the best so far (bounded by the mesh's bounding box) are skipped.
  // -infinity for no rows.
  double max_signed_distance(const Points3& points) const;
  // max_signed_distance(points) > threshold, for threshold >= 0, but cheaper: only inside
  // tests, a distance only for points inside, and it stops at the first such point.
  bool any_deeper_than(const Points3& points, double threshold) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bimart
