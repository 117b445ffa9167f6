// The stage graph: a pipeline YAML as read (GraphFile), and as validated (Graph).
//
//   name: smoke
//   seed: 0
//   plugins: [../build/libmy_stage.so]     # optional, relative to this file
//   vars:                                  # optional: name: default (a YAML value;
//     out: out/smoke                       #   empty = must be given with --var)
//     frames: 64
//   stages:
//     - id: trajectory                     # unique, [a-z_][a-z0-9_]*
//       use: trajectory.constant           # registered implementation
//       params: {frames: "${frames}"}   # a whole-value ${name} keeps the value's type
//     - id: write                          # (here an int); inside text it is spliced in
//       use: export.states_csv
//       params: {path: "${out}/states.csv"}
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

// A pipeline variable (`vars:`), referred to as ${name} in parameter values.
struct VarSetting {
  std::string name;
  YAML::Node value;     // the default, or the value given with --var; null: none yet
  SourceLocation where;  // of the default, or the --var that set it
  bool set = false;      // given on the command line
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
  std::vector<VarSetting> vars;
  std::vector<StageSetting> stages;

  static GraphFile load(const std::string& path);
  // `path` names the text in messages; relative plug-in paths resolve against `base_dir`.
  static GraphFile parse(const std::string& text, const std::string& path,
                         const std::string& base_dir = ".");

  // Applies "stage_id.param=value" (value in YAML, e.g. 64, 0.5, [1, 2], out.csv),
  // "stage_id.use=kind.name" (another implementation of the stage, e.g. encoder.use=encoder.u_bps)
  // or "seed=N". Unknown stages are reported here; unknown parameters at validation, with
  // the override as their location.
  void apply_override(const std::string& assignment);

  // Sets a variable declared under vars: from "name=value" (value in YAML). `origin` names
  // where it comes from in messages (e.g. "--var out=x", "--out"). A name the file does
  // not declare is an error naming the file, with close names.
  void set_var(const std::string& name, const std::string& value, const std::string& origin);
  void set_var(const std::string& assignment);  // "name=value", as --var gives it

  // `value` with every ${name} replaced: a scalar that is exactly "${name}" becomes the
  // variable's value (keeping its YAML type), "${a}/x" splices the value's text in,
  // "$${" stands for a literal "${"; lists and maps are substituted item by item.
  // Throws bimart::Error (without location) for an undeclared name or one with no value.
  YAML::Node substitute(const YAML::Node& value) const;
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
  std::vector<std::pair<std::string, std::string>> vars;  // name, value (YAML text)
  std::vector<GraphNode> nodes;  // in run order (dependencies first, then file order)

  const GraphNode& node(const std::string& id) const;
  // Human-readable listing: stages in run order, implementation, parameters, wiring.
  std::string describe() const;
  // The graph as a mermaid flowchart.
  std::string mermaid() const;
};

Graph validate(const GraphFile& file, const Registry& registry);

}  // namespace bimart
