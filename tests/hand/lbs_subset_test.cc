// lbs_subset (core/hand/lbs_subset.h) against the reference lbs(): the same vertices and
// joints, and the same Jet derivatives (its pose-corrective shortcut must lose nothing).
#include "core/hand/lbs_subset.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <random>

#include "tests/hand/synthetic_model.h"

namespace bimart {
namespace {

using Jet = ceres::Jet<double, 61>;

std::vector<double> random_inputs(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x(61);
  for (int i = 0; i < 48; ++i) x[i] = 0.6 * u(rng);
  for (int i = 48; i < 51; ++i) x[i] = 0.3 * u(rng);
  for (int i = 51; i < 61; ++i) x[i] = 2.0 * u(rng);
  return x;
}

TEST(LbsSubsetTest, ValuesEqualTheFullModelsRowsAndJoints) {
  const HandModel m = testing::make_synthetic_hand(40);
  const std::vector<int> ids = {39, 0, 7, 7, 21};  // any order, repeats allowed
  const LbsSubset sub = LbsSubset::from(m, ids);
  for (unsigned seed : {1u, 2u, 3u}) {
    const std::vector<double> x = random_inputs(seed);
    LbsResult<double> full;
    lbs(m, &x[0], &x[3], &x[48], &x[51], &full);
    std::vector<double> v(3 * ids.size()), J(48);
    lbs_subset(sub, &x[0], &x[3], &x[48], &x[51], v.data(), J.data());
    for (size_t s = 0; s < ids.size(); ++s)
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(v[3 * s + k], full.vertices(ids[s], k), 1e-12);
    for (int j = 0; j < 16; ++j)
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(J[3 * j + k], full.joints(j, k), 1e-12);
  }
}

// With and without pose correctives (the procedural hand has none: another code path).
TEST(LbsSubsetTest, JetDerivativesEqualPlainJetsThroughTheReference) {
  HandModel without = testing::make_synthetic_hand(40);
  without.posedirs.setZero();
  for (const HandModel& m : {testing::make_synthetic_hand(40), without}) {
  std::vector<int> ids(40);
  for (int i = 0; i < 40; ++i) ids[i] = i;
  const LbsSubset sub = LbsSubset::from(m, ids);
  EXPECT_EQ(sub.has_pose_correctives, &m != &without && m.posedirs.cwiseAbs().maxCoeff() > 0);
  for (unsigned seed : {4u, 5u}) {
    const std::vector<double> x0 = random_inputs(seed);
    std::vector<Jet> x(61);
    for (int i = 0; i < 61; ++i) x[i] = Jet(x0[i], i);
    LbsResult<Jet> ref;
    lbs(m, &x[0], &x[3], &x[48], &x[51], &ref);
    std::vector<Jet> v(3 * 40), J(48);
    lbs_subset(sub, &x[0], &x[3], &x[48], &x[51], v.data(), J.data());
    double worst = 0;
    for (int s = 0; s < 40; ++s)
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(v[3 * s + k].a, ref.vertices(s, k).a, 1e-12);
        worst = std::max(worst, (v[3 * s + k].v - ref.vertices(s, k).v).cwiseAbs().maxCoeff());
      }
    for (int j = 0; j < 16; ++j)
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, (J[3 * j + k].v - ref.joints(j, k).v).cwiseAbs().maxCoeff());
    EXPECT_LT(worst, 1e-11);
  }
  }
}

TEST(LbsSubsetTest, AFixedShapeGivesTheSameValuesWithNoShapeDerivatives) {
  const HandModel m = testing::make_synthetic_hand(30);
  const LbsSubset sub = LbsSubset::from(m, {3, 9, 27});
  const std::vector<double> x0 = random_inputs(6);
  using Jet51 = ceres::Jet<double, 51>;
  std::vector<Jet51> x(51);
  for (int i = 0; i < 51; ++i) x[i] = Jet51(x0[i], i);
  std::vector<Jet51> v(9);
  lbs_subset(sub, &x[0], &x[3], &x[48], &x0[51], v.data());
  std::vector<double> d(9);
  lbs_subset(sub, &x0[0], &x0[3], &x0[48], &x0[51], d.data());
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(v[i].a, d[i], 1e-12);
  // ... and the derivatives of the 51 inputs equal those with β as Jets too.
  std::vector<Jet> x61(61);
  for (int i = 0; i < 61; ++i) x61[i] = Jet(x0[i], i);
  std::vector<Jet> w(9);
  lbs_subset(sub, &x61[0], &x61[3], &x61[48], &x61[51], w.data());
  for (int i = 0; i < 9; ++i)
    for (int k = 0; k < 51; ++k) EXPECT_NEAR(v[i].v[k], w[i].v[k], 1e-12);
}

TEST(LbsSubsetTest, RejectsVerticesOutOfRange) {
  const HandModel m = testing::make_synthetic_hand(30);
  EXPECT_THROW(LbsSubset::from(m, {0, 30}), Error);
  EXPECT_THROW(LbsSubset::from(m, {-1}), Error);
}

}  // namespace
}  // namespace bimart
