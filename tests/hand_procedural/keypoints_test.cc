#include "core/hand/keypoints.h"

#include <gtest/gtest.h>

#include <set>

#include "core/util/error.h"
#include "tests/hand_procedural/fixture.h"

namespace bimart {
namespace {

TEST(HandKeypoints, HundredUniqueVerticesCoveringEveryPart) {
  const HandModel& m = test::right_hand();
  ASSERT_EQ(m.keypoints.size(), 100u);
  const std::set<int> unique(m.keypoints.begin(), m.keypoints.end());
  EXPECT_EQ(unique.size(), 100u);
  const std::vector<int> part = hand_parts(m);
  std::vector<int> per_part(16, 0);
  for (int k : m.keypoints) {
    ASSERT_GE(k, 0);
    ASSERT_LT(k, m.num_vertices());
    ++per_part[part[k]];
  }
  for (int p = 0; p < 16; ++p) EXPECT_GE(per_part[p], 2) << "part " << p;
  // The palm is by far the largest part, so it gets the most keypoints.
  EXPECT_EQ(std::max_element(per_part.begin(), per_part.end()) - per_part.begin(), 0);
}

TEST(HandKeypoints, SameForBothSidesAndDeterministic) {
  EXPECT_EQ(test::right_hand().keypoints, test::left_hand().keypoints);
  EXPECT_EQ(hand_keypoints(test::left_hand(), 100), test::right_hand().keypoints);
}

TEST(HandKeypoints, FarthestPointSamplingSpreadsThemOut) {
  // Within the palm no two keypoints are closer than 1 cm (the palm is ~9 x 8 cm).
  const HandModel& m = test::right_hand();
  const std::vector<int> part = hand_parts(m);
  std::vector<int> palm;
  for (int k : m.keypoints)
    if (part[k] == 0) palm.push_back(k);
  for (std::size_t i = 0; i < palm.size(); ++i)
    for (std::size_t j = i + 1; j < palm.size(); ++j)
      EXPECT_GT((m.v_template.row(palm[i]) - m.v_template.row(palm[j])).norm(), 0.01);
}

TEST(HandKeypoints, RejectsImpossibleCounts) {
  EXPECT_THROW(hand_keypoints(test::right_hand(), 10), Error);     // < 2 per part
  EXPECT_THROW(hand_keypoints(test::right_hand(), 100000), Error);  // > V
}

}  // namespace
}  // namespace bimart
