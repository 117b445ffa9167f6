#include <gtest/gtest.h>

#include "core/pipeline/params.h"
#include "core/pipeline/stage.h"

using namespace bimart;

TEST(Params, SchemaTypesFollowDefaults) {
  StageSpec s("kind.name", "help");
  s.param("flag", true, "").param("n", 3, "").param("x", 0.5, "").param("path", "a.csv", "")
      .param("v", std::vector<double>{1, 2}, "");
  ASSERT_EQ(s.params.size(), 5u);
  EXPECT_EQ(s.params[0].type, ParamType::Bool);
  EXPECT_EQ(s.params[1].type, ParamType::Int);
  EXPECT_EQ(s.params[2].type, ParamType::Float);
  EXPECT_EQ(s.params[3].type, ParamType::String);
  EXPECT_EQ(s.params[4].type, ParamType::FloatList);
}

TEST(Params, YamlTextOfValues) {
  EXPECT_EQ(to_yaml(ParamValue(true)), "true");
  EXPECT_EQ(to_yaml(ParamValue(std::int64_t{64})), "64");
  EXPECT_EQ(to_yaml(ParamValue(1.0)), "1.0");
  EXPECT_EQ(to_yaml(ParamValue(0.25)), "0.25");
  EXPECT_EQ(to_yaml(ParamValue(0.3)), "0.3");                       // not 0.29999999999999999
  EXPECT_EQ(to_yaml(ParamValue(0.1 + 0.2)), "0.30000000000000004");  // exact when needed
  EXPECT_EQ(to_yaml(ParamValue(std::string("a\"b"))), "\"a\\\"b\"");
  EXPECT_EQ(to_yaml(ParamValue(std::vector<double>{1, 2.5})), "[1.0, 2.5]");
}

TEST(Params, TypedAccessAndErrors) {
  Params p;
  p.set("frames", std::int64_t{64});
  EXPECT_EQ(p.integer("frames"), 64);
  try {
    p.number("frames");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "parameter 'frames' is an int, but was read as a float");
  }
  try {
    p.integer("frame");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'frames'"), std::string::npos) << e.what();
  }
}

TEST(StageSpec, CheckRejectsBadKeysAndDuplicates) {
  EXPECT_NO_THROW(StageSpec("encoder.np_bps", "").check());
  EXPECT_THROW(StageSpec("Encoder.np_bps", "").check(), Error);
  EXPECT_THROW(StageSpec("encoder", "").check(), Error);
  EXPECT_THROW(StageSpec("encoder.np-bps", "").check(), Error);
  StageSpec dup("a.b", "");
  dup.param("x", 1, "").param("x", 2, "");
  EXPECT_THROW(dup.check(), Error);
}
