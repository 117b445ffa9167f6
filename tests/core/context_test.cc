#include <gtest/gtest.h>

#include "core/pipeline/context.h"

using bimart::Context;
using bimart::Error;

TEST(Context, StoresAndReturnsTypedValues) {
  Context c;
  c.put("a.x", 2.5);
  c.put("a.name", std::string("box"));
  EXPECT_DOUBLE_EQ(c.get<double>("a.x"), 2.5);
  EXPECT_EQ(c.get<std::string>("a.name"), "box");
  EXPECT_EQ(c.type_of("a.x"), "float");
  EXPECT_EQ(c.keys(), (std::vector<std::string>{"a.name", "a.x"}));
}

TEST(Context, MissingNameIsAnErrorNamingItAndCloseNames) {
  Context c;
  c.put("encoder.object_features", 1.0);
  try {
    c.get<double>("encoder.object_feature");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'encoder.object_feature'"), std::string::npos) << m;
    EXPECT_NE(m.find("did you mean 'encoder.object_features'"), std::string::npos) << m;
  }
}

TEST(Context, WrongTypeIsAnErrorNamingBothTypes) {
  Context c;
  c.put("traj.fps", 30.0);
  try {
    c.get<std::string>("traj.fps");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'traj.fps'"), std::string::npos) << m;
    EXPECT_NE(m.find("'float'"), std::string::npos) << m;
    EXPECT_NE(m.find("'string'"), std::string::npos) << m;
  }
}

struct Custom {
  int x;
};

TEST(Context, CustomTypesUseTheirCppName) {
  Context c;
  c.put("s.custom", Custom{3});
  EXPECT_EQ(c.get<Custom>("s.custom").x, 3);
  EXPECT_EQ(c.type_of("s.custom"), "Custom");
  EXPECT_THROW(c.get<int>("s.custom"), Error);
}

TEST(Context, PutReplaces) {
  Context c;
  c.put("k", 1.0);
  c.put("k", std::string("now text"));
  EXPECT_EQ(c.type_of("k"), "string");
  EXPECT_EQ(c.size(), 1u);
}

TEST(Context, NarrowTypesHaveTheirOwnNames) {
  // int vs int64 and float vs double must not share a name, or validation would pass a
  // port that fails when read.
  EXPECT_EQ(bimart::type_name<std::int64_t>(), "int");
  EXPECT_EQ(bimart::type_name<int>(), "int32");
  EXPECT_EQ(bimart::type_name<double>(), "float");
  EXPECT_EQ(bimart::type_name<float>(), "float32");
  Context c;
  c.put("a.n", 3);
  EXPECT_THROW(c.get<std::int64_t>("a.n"), Error);
}
