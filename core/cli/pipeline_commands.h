// The pipeline sub-commands of `bimart`: run, graph, plugins, info, bench. Each returns
// the process exit code.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bimart::cli {

struct PipelineArgs {
  std::string pipeline;
  std::vector<std::string> overrides;  // stage.param=value
  std::vector<std::string> vars;       // name=value (--var)
  std::string out;                     // --out: the variable `out`, when given
  int samples = 0;                     // --samples: the variable `samples`, when > 0
  std::uint64_t seed = 0;              // with has_seed; else the pipeline's own
  bool has_seed = false;
};

int run(const PipelineArgs& args);
int graph(const PipelineArgs& args, bool mermaid);
int plugins(const std::string& kind, bool json);
int info();
int bench_blas(int size, int repeats);

// Loads the built-in plug-ins, BIMART_PLUGIN_PATH and the --plugin libraries.
void load_plugins(const std::vector<std::string>& extra);

std::string version_text();

}  // namespace bimart::cli
