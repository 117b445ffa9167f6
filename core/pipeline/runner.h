// Runs a validated graph: creates every stage first (so a bad parameter fails before any
// work), then runs them in order, each with its seeded generator, and checks that each
// stage wrote all of its declared outputs.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/pipeline/context.h"
#include "core/pipeline/graph.h"

namespace bimart {

struct StageTiming {
  std::string id;
  double seconds = 0.0;
};

struct RunOptions {
  // Called before each stage: index (0-based) and count.
  std::function<void(const GraphNode&, std::size_t, std::size_t)> on_stage;
};

struct RunResult {
  Context context;
  std::vector<StageTiming> timings;
};

RunResult run_graph(const Graph& graph, const RunOptions& options = {});

}  // namespace bimart
