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

TEST(Text, LowerIdentifiers) {
  EXPECT_TRUE(is_lower_identifier("np_bps2"));
  EXPECT_TRUE(is_lower_identifier("_hidden"));
  EXPECT_FALSE(is_lower_identifier("_hidden", false));
  EXPECT_FALSE(is_lower_identifier("2fast"));
  EXPECT_FALSE(is_lower_identifier("Upper"));
  EXPECT_FALSE(is_lower_identifier("with-dash"));
  EXPECT_FALSE(is_lower_identifier(""));
}
