// The pipeline sub-commands of `bimart`: run, graph, plugins, info, bench. Each returns
// the process exit code.
#pragma once

#include <string>
#include <vector>

namespace bimart::cli {

struct PipelineArgs {
  std::string pipeline;
  std::vector<std::string> overrides;  // stage.param=value
  long long seed = -1;                 // < 0: the pipeline's own
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
