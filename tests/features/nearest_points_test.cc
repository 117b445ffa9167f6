#include "core/geometry/nearest_points.h"

#include <gtest/gtest.h>

#include <random>

namespace bimart {
namespace {

Points3 random_cloud(int n, std::mt19937_64& rng, double scale) {
  std::normal_distribution<double> g(0.0, scale);
  Points3 p(n, 3);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) p(i, c) = g(rng);
  return p;
}

TEST(NearestPoints, EqualsBruteForceOnRandomClouds) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const int n = 50 + 400 * trial;
    const Points3 cloud = random_cloud(n, rng, 0.3);
    const Points3 queries = random_cloud(500, rng, 0.5);
    const NearestPoints tree(cloud);
    std::vector<int> idx(queries.rows());
    std::vector<double> d2(queries.rows());
    tree.nearest(queries, idx.data(), d2.data());
    for (int q = 0; q < queries.rows(); ++q) {
      Eigen::Index best;
      const double brute = (cloud.rowwise() - queries.row(q)).rowwise().squaredNorm().minCoeff(&best);
      // Random normal clouds have no ties: the index must match too.
      EXPECT_EQ(idx[q], best) << "trial " << trial << " query " << q;
      EXPECT_DOUBLE_EQ(d2[q], brute);
      const NearestPoints::Hit one = tree.nearest(queries.row(q).transpose());
      EXPECT_EQ(one.index, best);
    }
  }
}

TEST(NearestPoints, QueryOnAPointFindsItAtDistanceZero) {
  std::mt19937_64 rng(1);
  const Points3 cloud = random_cloud(300, rng, 1.0);
  const NearestPoints tree(cloud);
  for (int i = 0; i < cloud.rows(); i += 17) {
    const NearestPoints::Hit h = tree.nearest(cloud.row(i).transpose());
    EXPECT_EQ(h.index, i);
    EXPECT_EQ(h.distance_sq, 0.0);
  }
}

TEST(NearestPoints, EmptySetIsAnError) { EXPECT_ANY_THROW(NearestPoints(Points3(0, 3))); }

}  // namespace
}  // namespace bimart
