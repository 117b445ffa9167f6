// The stage graph: a pipeline YAML as read (GraphFile), and as validated (Graph).
//
//   name: smoke
//   seed: 0
//   plugins: [../build/libmy_stage.so]     # optional, relative to this file
//   stages:
//     - id: trajectory                     # unique, [a-z_][a-z0-9_]*
//       use: trajectory.constant           # registered implementation
//       params: {frames: 64}
//     - id: write
//       use: export.states_csv
//       inputs: {object_states: trajectory.object_states}   # optional: by default an
//                                           # input comes from the nearest earlier stage
//                                           # with an output of the same name
//
// Validation checks everything before anything runs and reports every problem with its
// file, line and column.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/pipeline/registry.h"
#include "core/util/error.h"

namespace bimart {

struct ParamSetting {
  std::string name;
  YAML::Node value;
  SourceLocation where;
};

struct InputSetting {
  std::string port;
  std::string source;  // "stage_id.output"
  SourceLocation where;
};

struct StageSetting {
  std::string id;
  SourceLocation where;
  std::string use;
  SourceLocation use_where;
  std::vector<ParamSetting> params;
  std::vector<InputSetting> inputs;
};

struct GraphFile {
  std::string path;  // as given; used in error messages
  std::string name;
  std::string description;
  std::uint64_t seed = 0;
  std::vector<std::pair<std::string, SourceLocation>> plugins;  // resolved against the file's folder
  std::vector<StageSetting> stages;

  static GraphFile load(const std::string& path);
  // `path` names the text in messages; relative plug-in paths resolve against `base_dir`.
  static GraphFile parse(const std::string& text, const std::string& path,
                         const std::string& base_dir = ".");

  // Applies "stage_id.param=value" (value in YAML, e.g. 64, 0.5, [1, 2], out.csv) or
  // "seed=N". Unknown stages are reported here; unknown parameters at validation, with
  // the override as their location.
  void apply_override(const std::string& assignment);
};

struct Binding {
  std::string port;
  std::string stage_id;  // producer
  std::string output;    // producer's output port
  bool implicit = false;
  SourceLocation where;
};

struct GraphNode {
  std::string id;
  const StageEntry* entry = nullptr;
  Params params;
  std::vector<Binding> inputs;
  SourceLocation where;
};

struct Graph {
  std::string path;
  std::string name;
  std::string description;
  std::uint64_t seed = 0;
  std::vector<GraphNode> nodes;  // in run order (dependencies first, then file order)

  const GraphNode& node(const std::string& id) const;
  // Human-readable listing: stages in run order, implementation, parameters, wiring.
  std::string describe() const;
  // The graph as a mermaid flowchart.
  std::string mermaid() const;
};

Graph validate(const GraphFile& file, const Registry& registry);

}  // namespace bimart
