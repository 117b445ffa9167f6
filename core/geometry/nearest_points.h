// Nearest-neighbour queries on a fixed 3-D point set (a k-d tree from nanoflann). Build it
// once per rigid point set and move the queries, not the points.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

class NearestPoints {
 public:
  // Copies the points; at least one is required.
  explicit NearestPoints(Points3 points);
  ~NearestPoints();
  NearestPoints(NearestPoints&&) noexcept;
  NearestPoints& operator=(NearestPoints&&) noexcept;

  struct Hit {
    int index = -1;
    double distance_sq = 0;
  };

  Hit nearest(const Eigen::Vector3d& query) const;
  // For each row of `queries`: the nearest point's index and squared distance.
  void nearest(const Points3& queries, int* indices, double* distances_sq) const;

  // The indices of every point closer than `radius` to `query`, in no particular order.
  void within(const Eigen::Vector3d& query, double radius, std::vector<int>* indices) const;

  const Points3& points() const;
  Eigen::Index size() const { return points().rows(); }

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

}  // namespace bimart
