#include <gtest/gtest.h>

#include "core/util/text.h"

using namespace bimart;

TEST(Text, EditDistanceKnownValues) {
  EXPECT_EQ(edit_distance("", ""), 0);
  EXPECT_EQ(edit_distance("abc", ""), 3);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3);
  EXPECT_EQ(edit_distance("np_bps", "npbps"), 1);
  EXPECT_EQ(edit_distance("flaw", "lawn"), 2);
}

TEST(Text, DidYouMeanListsCloseNamesBestFirst) {
  const std::vector<std::string> keys{"encoder.np_bps", "encoder.npa_bps", "encoder.u_bps", "refine.ceres"};
  EXPECT_EQ(did_you_mean("encoder.npbps", keys), " (did you mean 'encoder.np_bps', 'encoder.npa_bps' or 'encoder.u_bps'?)");
  EXPECT_EQ(did_you_mean("something.else", keys), "");
}
