// Graph loading and validation: every error names file:line:column.
#include <gtest/gtest.h>

#include "core/pipeline/graph.h"
#include "test_stages.h"

using namespace bimart;

namespace {

const Registry& registry() {
  static const Registry r = test::make_registry();
  return r;
}

Graph load(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
  GraphFile f = GraphFile::parse(yaml, "test.yaml");
  for (const auto& o : overrides) f.apply_override(o);
  return validate(f, registry());
}

// The message of the error `yaml` raises (fails the test if it raises none).
std::string error_of(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
  try {
    load(yaml, overrides);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for:\n" << yaml;
  return "";
}

#define EXPECT_HAS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "message: " << (haystack)

const char* kGood = R"(name: good
seed: 7
stages:
  - id: src
    use: test.source
    params: {value: 2.5}
  - id: twice
    use: test.double
  - id: out
    use: test.sink
    inputs: {value: twice.value}
)";

}  // namespace

TEST(Graph, ValidGraphResolvesDefaultsAndWiring) {
  const Graph g = load(kGood);
  EXPECT_EQ(g.name, "good");
  EXPECT_EQ(g.seed, 7u);
  ASSERT_EQ(g.nodes.size(), 3u);
  EXPECT_DOUBLE_EQ(g.node("src").params.number("value"), 2.5);
  EXPECT_EQ(g.node("src").params.integer("count"), 3);  // default filled in
  const auto& twice = g.node("twice").inputs;
  ASSERT_EQ(twice.size(), 1u);
  EXPECT_EQ(twice[0].stage_id, "src");  // by name
  EXPECT_TRUE(twice[0].implicit);
  EXPECT_EQ(g.node("out").inputs[0].stage_id, "twice");
  EXPECT_FALSE(g.node("out").inputs[0].implicit);
  EXPECT_HAS(g.describe(), "value <- twice.value");
  EXPECT_HAS(g.mermaid(), "src -- value --> twice");
}

TEST(Graph, UnknownImplementationNamesLineAndCloseNames) {
  const std::string m = error_of(R"(stages:
  - id: src
    use: test.sourc
)");
  EXPECT_HAS(m, "test.yaml:3:10:");
  EXPECT_HAS(m, "unknown implementation 'test.sourc'");
  EXPECT_HAS(m, "did you mean 'test.source'");
}

TEST(Graph, UnknownParameter) {
  const std::string m = error_of(R"(stages:
  - id: src
    use: test.source
    params:
      valeu: 3.0
)");
  EXPECT_HAS(m, "test.yaml:5:7:");
  EXPECT_HAS(m, "has no parameter 'valeu'");
  EXPECT_HAS(m, "did you mean 'value'");
}

TEST(Graph, MistypedParameterPointsAtTheValue) {
  const std::string m = error_of(R"(stages:
  - id: src
    use: test.source
    params:
      count: 2.5
)");
  EXPECT_HAS(m, "test.yaml:5:14:");
  EXPECT_HAS(m, "parameter 'count' expects an int, got '2.5'");
  const std::string list = error_of(R"(stages:
  - id: src
    use: test.source
    params: {value: [1, 2]}
)");
  EXPECT_HAS(list, "test.yaml:4:21:");
  EXPECT_HAS(list, "expects a float");
}

TEST(Graph, IntegersAreAcceptedAsFloats) {
  const Graph g = load("stages:\n  - {id: src, use: test.source, params: {value: 4}}\n");
  EXPECT_DOUBLE_EQ(g.node("src").params.number("value"), 4.0);
}

TEST(Graph, MissingInput) {
  const std::string m = error_of(R"(stages:
  - id: twice
    use: test.double
)");
  EXPECT_HAS(m, "test.yaml:2:5:");
  EXPECT_HAS(m, "missing input 'value'");
}

TEST(Graph, InputOnlyProducedByALaterStage) {
  const std::string m = error_of(R"(stages:
  - id: twice
    use: test.double
  - id: src
    use: test.source
)");
  EXPECT_HAS(m, "test.yaml:2:5:");
  EXPECT_HAS(m, "no earlier stage produces it (only later 'src')");
}

TEST(Graph, ExplicitInputFromAStageWithoutThatOutput) {
  const std::string m = error_of(R"(stages:
  - id: src
    use: test.source
  - id: out
    use: test.sink
    inputs:
      value: src.valu
)");
  EXPECT_HAS(m, "test.yaml:7:14:");
  EXPECT_HAS(m, "stage 'src' (test.source) produces no 'valu'");
  EXPECT_HAS(m, "did you mean 'value'");
}

TEST(Graph, ExplicitInputFromAnUnknownStage) {
  const std::string m = error_of(R"(stages:
  - id: src
    use: test.source
  - id: out
    use: test.sink
    inputs: {value: sorce.value}
)");
  EXPECT_HAS(m, "test.yaml:6:21:");
  EXPECT_HAS(m, "comes from stage 'sorce', which is not in the pipeline");
  EXPECT_HAS(m, "did you mean 'src'");
}

TEST(Graph, UnknownInputPort) {
  const std::string m = error_of(R"(stages:
  - id: src
    use: test.source
  - id: out
    use: test.sink
    inputs: {valeu: src.value}
)");
  EXPECT_HAS(m, "test.yaml:6:21:");
  EXPECT_HAS(m, "has no input 'valeu'");
}

TEST(Graph, TypeMismatchBetweenPorts) {
  const std::string m = error_of(R"(stages:
  - id: text
    use: test.text
  - id: twice
    use: test.double
    inputs: {value: text.value}
)");
  EXPECT_HAS(m, "test.yaml:6:21:");
  EXPECT_HAS(m, "expects 'float', but text.value is 'string'");
  const std::string by_name = error_of(R"(stages:
  - id: text
    use: test.text
  - id: twice
    use: test.double
)");
  EXPECT_HAS(by_name, "test.yaml:4:5:");
  EXPECT_HAS(by_name, "gives 'string'");
}

TEST(Graph, Cycle) {
  const std::string m = error_of(R"(stages:
  - id: a
    use: test.cycle_a
    inputs: {a: b.a}
  - id: b
    use: test.cycle_b
    inputs: {b: a.b}
)");
  EXPECT_HAS(m, "the stages form a cycle: ");
  EXPECT_TRUE(m.find("a -> b -> a") != std::string::npos || m.find("b -> a -> b") != std::string::npos) << m;
  EXPECT_TRUE(m.find("test.yaml:2:5:") != std::string::npos || m.find("test.yaml:5:5:") != std::string::npos) << m;
}

TEST(Graph, SelfLoopIsACycle) {
  const std::string m = error_of(R"(stages:
  - id: src
    use: test.source
  - id: twice
    use: test.double
    inputs: {value: twice.value}
)");
  EXPECT_HAS(m, "test.yaml:4:5:");
  EXPECT_HAS(m, "cycle: twice -> twice");
}

TEST(Graph, ByNameWiringSkipsProducersOfAnotherType) {
  const Graph g = load(R"(stages:
  - {id: src, use: test.source}
  - {id: text, use: test.text}
  - {id: twice, use: test.double}
)");
  EXPECT_EQ(g.node("twice").inputs[0].stage_id, "src");
}

TEST(Graph, LaterProducersRunFirstWhenWiredExplicitly) {
  const Graph g = load(R"(stages:
  - id: twice
    use: test.double
    inputs: {value: src.value}
  - id: src
    use: test.source
)");
  ASSERT_EQ(g.nodes.size(), 2u);
  EXPECT_EQ(g.nodes[0].id, "src");
  EXPECT_EQ(g.nodes[1].id, "twice");
}

TEST(Graph, DuplicateIds) {
  const std::string m = error_of(R"(stages:
  - id: src
    use: test.source
  - id: src
    use: test.source
)");
  EXPECT_HAS(m, "test.yaml:4:5:");
  EXPECT_HAS(m, "duplicate stage id 'src' (first used at test.yaml:2:5)");
}

TEST(Graph, SeveralProblemsAreReportedTogether) {
  const std::string m = error_of(R"(stages:
  - id: src
    use: test.source
    params: {nope: 1}
  - id: bad
    use: test.nothing
)");
  EXPECT_HAS(m, "2 problems");
  EXPECT_HAS(m, "test.yaml:4:14:");
  EXPECT_HAS(m, "test.yaml:6:10:");
}

TEST(Graph, StructuralErrors) {
  EXPECT_HAS(error_of("stages: [\n"), "test.yaml:");
  EXPECT_HAS(error_of("stages: []\n"), "'stages' must be a non-empty list");
  EXPECT_HAS(error_of("stage:\n  - {id: a, use: test.source}\n"), "test.yaml:1:1: unknown key 'stage'");
  EXPECT_HAS(error_of("stages:\n  - {id: a, uses: test.source}\n"), "test.yaml:2:13: unknown key 'uses'");
  EXPECT_HAS(error_of("stages:\n  - {use: test.source}\n"), "has no 'id'");
  EXPECT_HAS(error_of("stages:\n  - {id: A-1, use: test.source}\n"), "test.yaml:2:10:");
  EXPECT_HAS(error_of("seed: -3\nstages:\n  - {id: a, use: test.source}\n"), "test.yaml:1:7:");
}

TEST(Graph, OverridesReplaceAndAddParameters) {
  const Graph g = load(kGood, {"src.value=9", "src.count=5", "seed=11"});
  EXPECT_DOUBLE_EQ(g.node("src").params.number("value"), 9.0);
  EXPECT_EQ(g.node("src").params.integer("count"), 5);
  EXPECT_EQ(g.seed, 11u);
}

TEST(Graph, YamlTextParametersTakeScalarsListsAndMappings) {
  EXPECT_EQ(load(kGood).node("src").params.string("extra"), "");
  EXPECT_EQ(load(kGood, {"src.extra=notes.yaml"}).node("src").params.string("extra"), "notes.yaml");
  EXPECT_EQ(load(kGood, {"src.extra={right: [{frames: [0, 4], part: top}]}"}).node("src").params.string("extra"),
            "{right: [{frames: [0, 4], part: top}]}");
  const std::string in_file = std::string(kGood).replace(std::string(kGood).find("{value: 2.5}"), 12,
                                                        "{value: 2.5, extra: [1, {a: b}]}");
  EXPECT_EQ(load(in_file).node("src").params.string("extra"), "[1, {a: b}]");
  // Other parameters still refuse a mapping.
  EXPECT_HAS(error_of(kGood, {"src.count={a: 1}"}), "parameter 'count' expects an int, got a list or mapping");
}

TEST(Graph, OverrideErrorsNameTheOverride) {
  EXPECT_HAS(error_of(kGood, {"src.valeu=9"}), "--set src.valeu=9: stage 'src' (test.source) has no parameter 'valeu'");
  EXPECT_HAS(error_of(kGood, {"src.count=abc"}), "--set src.count=abc: stage 'src' parameter 'count' expects an int, got 'abc'");
  EXPECT_HAS(error_of(kGood, {"scr.value=1"}), "no stage 'scr'");
  EXPECT_HAS(error_of(kGood, {"value=1"}), "names no stage parameter");
  EXPECT_HAS(error_of(kGood, {"seed=x"}), "seed must be a non-negative integer");
}

TEST(Graph, PluginPathsResolveAgainstTheFilesFolder) {
  const GraphFile f = GraphFile::parse("plugins: [lib/a.so, /abs/b.so]\nstages:\n  - {id: a, use: test.source}\n",
                                       "dir/p.yaml", "dir");
  ASSERT_EQ(f.plugins.size(), 2u);
  EXPECT_EQ(f.plugins[0].first, "dir/lib/a.so");
  EXPECT_EQ(f.plugins[1].first, "/abs/b.so");
  EXPECT_EQ(f.plugins[0].second.line, 1);
}

// Pipeline variables (vars:, ${name}, --var).
namespace {
const char* kVars = R"(vars:
  value: 2.5
  out: out/x
  label: hello
stages:
  - id: src
    use: test.source
    params: {value: "${value}"}
  - id: text
    use: test.text
  - id: sink
    use: test.sink
    params: {}
)";

GraphFile vars_file(const std::string& yaml = kVars) { return GraphFile::parse(yaml, "test.yaml"); }
}  // namespace

TEST(GraphVars, WholeValueKeepsTheTypeAndTextIsSpliced) {
  GraphFile f = vars_file();
  EXPECT_DOUBLE_EQ(validate(f, registry()).node("src").params.number("value"), 2.5);
  const YAML::Node spliced = f.substitute(YAML::Node("${out}/a_${label}.npz"));
  EXPECT_EQ(spliced.Scalar(), "out/x/a_hello.npz");
  EXPECT_EQ(f.substitute(YAML::Node("cost $$5 and $${out}")).Scalar(), "cost $$5 and ${out}");
  EXPECT_EQ(f.substitute(YAML::Load("[\"${out}\", 2]"))[0].Scalar(), "out/x");
  f.set_var("value=4");  // as --var value=4
  const Graph g = validate(f, registry());
  EXPECT_DOUBLE_EQ(g.node("src").params.number("value"), 4.0);
  EXPECT_HAS(g.describe(), "vars: value = 4, out = out/x, label = hello");
}

TEST(GraphVars, OverridesMaySubstituteToo) {
  GraphFile f = vars_file();
  f.apply_override("src.value=${value}");
  f.set_var("value", "7", "--samples 7");
  EXPECT_DOUBLE_EQ(validate(f, registry()).node("src").params.number("value"), 7.0);
}

TEST(GraphVars, UnknownVariableOnTheCommandLineIsAnErrorWithCloseNames) {
  GraphFile f = vars_file();
  try {
    f.set_var("valeu=3");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_HAS(e.what(), "--var valeu=3");
    EXPECT_HAS(e.what(), "test.yaml has no variable 'valeu'");
    EXPECT_HAS(e.what(), "did you mean 'value'");
    EXPECT_HAS(e.what(), "its variables: value, out, label");
  }
  GraphFile none = GraphFile::parse("stages:\n  - {id: src, use: test.source}\n", "plain.yaml");
  try {
    none.set_var("out", "x", "--out x");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_HAS(e.what(), "plain.yaml has no variable 'out'; it declares none");
  }
  EXPECT_THROW(f.set_var("novalue"), Error);
}

TEST(GraphVars, UndeclaredVariableNamesTheFileAndLine) {
  const std::string m = error_of(R"(vars:
  value: 1
stages:
  - id: src
    use: test.source
    params:
      value: ${vlue}
)");
  EXPECT_HAS(m, "test.yaml:7:14:");
  EXPECT_HAS(m, "stage 'src' parameter 'value'");
  EXPECT_HAS(m, "'${vlue}' names no variable of test.yaml (did you mean 'value'?)");
}

TEST(GraphVars, VariableWithoutValueMustBeGiven) {
  const char* yaml = R"(vars:
  value:
stages:
  - id: src
    use: test.source
    params: {value: "${value}"}
)";
  EXPECT_HAS(error_of(yaml), "variable 'value' has no value: give it with --var value=VALUE");
  GraphFile f = vars_file(yaml);
  f.set_var("value=1.5");
  EXPECT_DOUBLE_EQ(validate(f, registry()).node("src").params.number("value"), 1.5);
}

TEST(GraphVars, BadValuesAndNames) {
  // A value of the wrong type says where it came from.
  GraphFile f = vars_file();
  f.set_var("value=abc");
  try {
    validate(f, registry());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_HAS(e.what(), "test.yaml:8:21: stage 'src' parameter 'value' expects a float, got 'abc' (from '${value}')");
  }
  EXPECT_HAS(error_of("vars: {Bad: 1}\nstages:\n  - {id: src, use: test.source}\n"),
             "variable name 'Bad' must be lower case");
  EXPECT_HAS(error_of("vars: [a]\nstages:\n  - {id: src, use: test.source}\n"), "'vars' must be a mapping");
  EXPECT_HAS(error_of("vars: {v: 1}\nstages:\n  - {id: src, use: test.source, params: {value: \"${v\"}}\n"),
             "without its closing '}'");
}
