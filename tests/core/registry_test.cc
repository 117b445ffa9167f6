#include <gtest/gtest.h>

#include "core/pipeline/registry.h"

using namespace bimart;

namespace {
StageEntry make(const std::string& key, const std::string& lib) {
  return {StageSpec(key, "x"), [](const Params&) -> std::unique_ptr<Stage> { return nullptr; }, lib};
}
}  // namespace

TEST(Registry, UnknownKeyListsCloseNames) {
  Registry r;
  r.add(make("encoder.np_bps", "libA.so"));
  r.add(make("encoder.u_bps", "libA.so"));
  EXPECT_EQ(&r.get("encoder.np_bps"), r.find("encoder.np_bps"));
  try {
    r.get("encoder.npbps");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no stage 'encoder.npbps' (did you mean 'encoder.np_bps'"), std::string::npos)
        << e.what();
  }
}

TEST(Registry, DuplicateNamesBothLibrariesAndAddsNothing) {
  Registry r;
  r.add(make("encoder.np_bps", "libA.so"));
  std::vector<StageEntry> batch;
  batch.push_back(make("encoder.fresh", "libB.so"));
  batch.push_back(make("encoder.np_bps", "libB.so"));
  try {
    r.add(std::move(batch));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("duplicate stage 'encoder.np_bps': registered by libA.so and again by libB.so"),
              std::string::npos) << e.what();
  }
  EXPECT_EQ(r.find("encoder.fresh"), nullptr);
  EXPECT_EQ(r.size(), 1u);
}

TEST(Registry, DuplicateWithinOneBatch) {
  Registry r;
  std::vector<StageEntry> batch;
  batch.push_back(make("a.b", "libC.so"));
  batch.push_back(make("a.b", "libC.so"));
  EXPECT_THROW(r.add(std::move(batch)), Error);
  EXPECT_EQ(r.size(), 0u);
}

TEST(Registry, MalformedKeyIsRefused) {
  Registry r;
  EXPECT_THROW(r.add(make("NoDot", "libD.so")), Error);
}
