#include "core/pipeline/runner.h"

#include <chrono>
#include <memory>

#include "core/util/log.h"

namespace bimart {

namespace {

std::string label(const GraphNode& n) { return "stage '" + n.id + "' (" + n.entry->spec.key + ")"; }

template <class F>
void with_stage_context(const GraphNode& n, const char* doing, F&& f) {
  try {
    f();
  } catch (const Error& e) {
    throw Error(n.where, label(n) + " failed " + doing + ": " + e.what());
  } catch (const std::exception& e) {
    throw Error(n.where, label(n) + " failed " + doing + ": " + e.what());
  }
}

}  // namespace

RunResult run_graph(const Graph& graph, const RunOptions& options) {
  std::vector<std::unique_ptr<Stage>> stages;
  for (const auto& n : graph.nodes)
    with_stage_context(n, "to start", [&] { stages.push_back(n.entry->factory(n.params)); });

  RunResult result;
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    const GraphNode& n = graph.nodes[i];
    if (options.on_stage) options.on_stage(n, i, graph.nodes.size());
    std::vector<std::pair<std::string, std::string>> inputs;
    for (const auto& b : n.inputs) inputs.emplace_back(b.port, b.stage_id + "." + b.output);
    StageIO io(result.context, n.entry->spec, n.id, std::move(inputs), n.params,
               stage_seed(graph.seed, n.id));
    const auto t0 = std::chrono::steady_clock::now();
    with_stage_context(n, "while running", [&] { stages[i]->run(io); });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (const auto& out : n.entry->spec.outputs)
      if (!result.context.has(io.output_key(out.name)))
        throw Error(n.where, label(n) + " finished without writing its output '" + out.name + "'");
    result.timings.push_back({n.id, seconds});
    log::debug("{} took {:.3f} s", label(n), seconds);
  }
  return result;
}

}  // namespace bimart
