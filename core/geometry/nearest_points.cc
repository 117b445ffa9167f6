#include "core/geometry/nearest_points.h"

#include <nanoflann.hpp>

#include "core/geometry/point_guard.h"
#include "core/util/error.h"

namespace bimart {

struct NearestPoints::Tree {
  // nanoflann's data-set interface over the row-major point matrix.
  struct Cloud {
    Points3 pts;
    std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(pts.rows()); }
    double kdtree_get_pt(std::size_t i, std::size_t d) const { return pts(static_cast<Eigen::Index>(i), d); }
    template <class Box>
    bool kdtree_get_bbox(Box&) const { return false; }
  };
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3, std::uint32_t>;

  explicit Tree(Points3 points) : cloud{std::move(points)}, index(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10)) {
    index.buildIndex();
  }

  Cloud cloud;
  Index index;
};

NearestPoints::NearestPoints(Points3 points) {
  if (points.rows() == 0) throw Error("nearest-point search needs at least one point");
  check_points(points, "nearest-point search");
  tree_ = std::make_unique<Tree>(std::move(points));
}

NearestPoints::~NearestPoints() = default;
NearestPoints::NearestPoints(NearestPoints&&) noexcept = default;
NearestPoints& NearestPoints::operator=(NearestPoints&&) noexcept = default;

const Points3& NearestPoints::points() const { return tree_->cloud.pts; }

NearestPoints::Hit NearestPoints::nearest(const Eigen::Vector3d& q) const {
  check_point(q, "nearest-point query");
  std::uint32_t index = 0;
  double d2 = 0;
  const double query[3] = {q.x(), q.y(), q.z()};
  tree_->index.knnSearch(query, 1, &index, &d2);
  return {static_cast<int>(index), d2};
}

void NearestPoints::nearest(const Points3& queries, int* indices, double* distances_sq) const {
  check_points(queries, "nearest-point query");
  for (Eigen::Index i = 0; i < queries.rows(); ++i) {
    std::uint32_t index = 0;
    double d2 = 0;
    tree_->index.knnSearch(queries.row(i).data(), 1, &index, &d2);
    indices[i] = static_cast<int>(index);
    distances_sq[i] = d2;
  }
}

void NearestPoints::within(const Eigen::Vector3d& q, double radius, std::vector<int>* indices) const {
  check_point(q, "nearest-point query");
  const double query[3] = {q.x(), q.y(), q.z()};
  std::vector<std::pair<std::uint32_t, double>> hits;
  // L2_Simple_Adaptor compares squared distances: the radius goes in squared.
  tree_->index.radiusSearch(query, radius * radius, hits, nanoflann::SearchParams(32, 0, false));
  indices->clear();
  for (const auto& h : hits)
    if (h.second < radius * radius) indices->push_back(static_cast<int>(h.first));
}

}  // namespace bimart
