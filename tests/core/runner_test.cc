#include <gtest/gtest.h>

#include "core/pipeline/runner.h"
#include "test_stages.h"

using namespace bimart;

namespace {

const Registry& registry() {
  static const Registry r = test::make_registry();
  return r;
}

RunResult run_yaml(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
  GraphFile f = GraphFile::parse(yaml, "run.yaml");
  for (const auto& o : overrides) f.apply_override(o);
  return run_graph(validate(f, registry()));
}

std::vector<std::int64_t> draws(const RunResult& r, const std::string& id) {
  return r.context.get<std::vector<std::int64_t>>(id + ".draws");
}

const char* kRandom = R"(seed: 3
stages:
  - {id: r1, use: test.random}
  - {id: r2, use: test.random}
)";

}  // namespace

TEST(Runner, DataFlowsThroughTheContext) {
  const RunResult r = run_yaml(R"(stages:
  - {id: src, use: test.source, params: {value: 1.5}}
  - {id: twice, use: test.double}
  - {id: again, use: test.double}
  - {id: out, use: test.sink}
)");
  EXPECT_DOUBLE_EQ(r.context.get<double>("again.value"), 6.0);
  EXPECT_EQ(r.context.get<std::string>("out.result"), std::to_string(6.0));
  EXPECT_EQ(r.timings.size(), 4u);
}

TEST(Runner, OptionalInputsAreSeenWhenWired) {
  const RunResult r = run_yaml(R"(stages:
  - {id: src, use: test.source}
  - {id: text, use: test.text}
  - {id: out, use: test.sink, inputs: {extra: text.value}}
)");
  EXPECT_EQ(r.context.get<std::string>("out.result"), std::to_string(1.0) + "hello");
}

TEST(Runner, SameSeedSameNumbersOtherSeedOthers) {
  const auto a = run_yaml(kRandom), b = run_yaml(kRandom), c = run_yaml(kRandom, {"seed=4"});
  EXPECT_EQ(draws(a, "r1"), draws(b, "r1"));
  EXPECT_EQ(draws(a, "r2"), draws(b, "r2"));
  EXPECT_NE(draws(a, "r1"), draws(c, "r1"));
  EXPECT_NE(draws(a, "r1"), draws(a, "r2"));  // each stage has its own stream
}

TEST(Runner, AStagesStreamDoesNotDependOnOtherStages) {
  const auto both = run_yaml(kRandom);
  const auto alone = run_yaml("seed: 3\nstages:\n  - {id: r2, use: test.random}\n");
  EXPECT_EQ(draws(both, "r2"), draws(alone, "r2"));
  EXPECT_EQ(stage_seed(3, "r2"), stage_seed(3, "r2"));
  EXPECT_NE(stage_seed(3, "r2"), stage_seed(3, "r1"));
}

TEST(Runner, StageThatForgetsAnOutputIsAnError) {
  try {
    run_yaml("stages:\n  - {id: lazy, use: test.lazy}\n");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("run.yaml:2:5: stage 'lazy' (test.lazy) finished without writing its output 'value'"),
              std::string::npos) << e.what();
  }
}

TEST(Runner, BadParameterFailsBeforeAnyStageRuns) {
  // `first` would write a file if it ran; the strict stage's constructor must fail first.
  int started = 0;
  GraphFile f = GraphFile::parse(
      "stages:\n  - {id: first, use: test.source}\n  - {id: s, use: test.strict, params: {positive: -1}}\n", "run.yaml");
  RunOptions o;
  o.on_stage = [&](const GraphNode&, std::size_t, std::size_t) { ++started; };
  try {
    run_graph(validate(f, registry()), o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("run.yaml:3:5: stage 's' (test.strict) failed to start: positive must be > 0"),
              std::string::npos) << e.what();
  }
  EXPECT_EQ(started, 0);
}
