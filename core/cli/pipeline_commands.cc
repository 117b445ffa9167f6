#include "core/cli/pipeline_commands.h"

#include "core/cli/command.h"
#include "core/cli/common_options.h"

#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "core/pipeline/graph.h"
#include "core/pipeline/plugin_abi.h"
#include "core/pipeline/plugin_loader.h"
#include "core/pipeline/runner.h"
#include "core/runtime/blas.h"
#include "core/util/log.h"
#include "core/version.h"

namespace bimart::cli {

namespace {

// Reads the pipeline, applies overrides, loads the libraries it names, validates it.
Graph load_graph(const PipelineArgs& args) {
  GraphFile file = GraphFile::load(args.pipeline);
  for (const auto& v : args.vars) file.set_var(v);
  if (!args.out.empty()) file.set_var("out", args.out, "--out " + args.out);
  if (args.samples > 0) file.set_var("samples", std::to_string(args.samples), "--samples " + std::to_string(args.samples));
  for (const auto& o : args.overrides) file.apply_override(o);
  if (args.has_seed) file.seed = args.seed;
  for (const auto& [lib, where] : file.plugins) {
    try {
      PluginLoader::global().load(lib);
    } catch (const Error& e) {
      throw Error(where, e.message());
    }
  }
  return validate(file, Registry::global());
}

}  // namespace

std::string version_text() {
  return fmt::format("bimart {} (libtorch {}, plug-in ABI {})\n{}", BIMART_VERSION_STRING,
                     BIMART_TORCH_VERSION, BIMART_PLUGIN_ABI_VERSION,
                     runtime::describe(runtime::blas_info()));
}

void load_plugins(const std::vector<std::string>& extra) {
  PluginLoader& loader = PluginLoader::global();
  loader.load_startup();
  for (const auto& lib : extra) loader.load(lib);
  if (Registry::global().size() == 0)
    log::warn("no stages registered: no plug-ins found in {} (set BIMART_PLUGIN_PATH?)", builtin_plugin_dir());
}

int run(const PipelineArgs& args) {
  const Graph g = load_graph(args);
  log::info("pipeline '{}': {} stages, seed {}", g.name, g.nodes.size(), g.seed);
  RunOptions options;
  options.on_stage = [](const GraphNode& n, std::size_t i, std::size_t count) {
    log::info("[{}/{}] {} ({})", i + 1, count, n.id, n.entry->spec.key);
  };
  const RunResult result = run_graph(g, options);
  double total = 0;
  for (const auto& t : result.timings) total += t.seconds;
  // Each file written: a stage's `paths` (several files, e.g. one per sample), else its `path`.
  for (const auto& n : g.nodes) {
    if (const PortSpec* p = n.entry->spec.find_output("paths"); p && p->type == type_name<std::vector<std::string>>()) {
      for (const auto& file : result.context.get<std::vector<std::string>>(n.id + ".paths"))
        std::cout << "wrote " << file << "\n";
    } else if (const PortSpec* q = n.entry->spec.find_output("path"); q && q->type == type_name<std::string>()) {
      std::cout << "wrote " << result.context.get<std::string>(n.id + ".path") << "\n";
    }
  }
  log::info("done in {:.2f} s", total);
  return 0;
}

int graph(const PipelineArgs& args, bool mermaid) {
  const Graph g = load_graph(args);
  std::cout << (mermaid ? g.mermaid() : g.describe());
  return 0;
}

int plugins(const std::string& kind, bool json) {
  nlohmann::json all = nlohmann::json::array();
  int shown = 0;
  for (const StageEntry* e : Registry::global().entries()) {
    const StageSpec& s = e->spec;
    if (!kind.empty() && s.kind() != kind) continue;
    ++shown;
    if (json) {
      nlohmann::json j{{"key", s.key}, {"kind", s.kind()}, {"name", s.name()}, {"help", s.help},
                       {"library", e->library}};
      for (const auto& p : s.params)
        j["params"].push_back({{"name", p.name}, {"type", to_string(p.type)},
                               {"default", to_yaml(p.default_value)}, {"help", p.help}});
      for (const auto* ports : {&s.inputs, &s.outputs})
        for (const auto& p : *ports)
          j[ports == &s.inputs ? "inputs" : "outputs"].push_back(
              {{"name", p.name}, {"type", p.type}, {"optional", p.optional}, {"help", p.help}});
      all.push_back(j);
      continue;
    }
    std::cout << s.key << "  (kind " << s.kind() << ")  " << s.help << "\n";
    std::cout << "    library: " << e->library << "\n";
    for (const auto& p : s.params)
      std::cout << fmt::format("    param  {:<14} {:<11} = {:<16} {}\n", p.name, to_string(p.type),
                               to_yaml(p.default_value), p.help);
    for (const auto& p : s.inputs)
      std::cout << fmt::format("    in     {:<14} {}{}: {}\n", p.name, p.type, p.optional ? " (optional)" : "",
                               p.help);
    for (const auto& p : s.outputs) std::cout << fmt::format("    out    {:<14} {}: {}\n", p.name, p.type, p.help);
    std::cout << "\n";
  }
  if (json) std::cout << all.dump(2) << "\n";
  if (shown == 0 && !kind.empty()) {
    log::error("no stage of kind '{}' is registered", kind);
    return 1;
  }
  return 0;
}

int info() {
  std::cout << version_text() << "\n";
  std::cout << "built-in plug-ins: " << builtin_plugin_dir() << "\n";
  for (const auto& lib : PluginLoader::global().libraries())
    std::cout << "  " << lib.path << " (" << lib.stages.size() << (lib.stages.size() == 1 ? " stage)\n" : " stages)\n");
  return 0;
}

int bench_blas(int size, int repeats) {
  const runtime::BlasInfo b = runtime::blas_info();
  std::cout << runtime::describe(b) << "\n";
  const auto line = [](const char* what, const runtime::MatmulBench& r) {
    return fmt::format("{0:<18} {1}x{1} float32, {2} repeats: median {3:.4f} s, max {4:.4f} s, {5:.1f} GFLOP/s\n",
                       what, r.n, r.repeats, r.seconds_median, r.seconds_max, r.gflops_median);
  };
  const runtime::MatmulBench r = runtime::bench_matmul(size, repeats);
  std::cout << line("libtorch matmul", r);
  if (b.config.empty()) return 0;  // no OpenBLAS to compare with
  const runtime::MatmulBench direct = runtime::bench_openblas_direct(size, repeats);
  std::cout << line("OpenBLAS direct", direct);
  const double ratio = direct.gflops_median > 0 ? r.gflops_median / direct.gflops_median : 0.0;
  std::cout << fmt::format("libtorch / OpenBLAS direct: {:.0f} %\n", 100.0 * ratio);
  if (ratio < 0.8) {
    std::cout << "warning: libtorch reaches less than 80 % of OpenBLAS called directly"
              << (b.sgemm_in_openblas ? "" : " (its sgemm_ is not OpenBLAS's, see above)") << "\n";
  }
  return 0;
}

void add_pipeline_commands(CLI::App& app, Commands& out) {
  // Options of run and graph share one struct: only one sub-command runs per call.
  static PipelineArgs pa;
  auto add_pipeline_args = [&](CLI::App* cmd) {
    cmd->add_option("pipeline", pa.pipeline, "pipeline YAML file")->required()->check(CLI::ExistingFile);
    cmd->add_option("--set", pa.overrides, "override a parameter: stage.param=value (repeatable)");
    cmd->add_option("--var", pa.vars, "set a pipeline variable (vars:): name=value (repeatable)");
    cmd->add_option("--out", pa.out, "output folder: sets the variable 'out'");
    cmd->add_option("--samples", pa.samples, "samples generated at once: sets the variable 'samples'")
        ->check(CLI::Range(1, 1024));
    add_seed_option(cmd, pa.seed, "override the pipeline's seed")->each([](const std::string&) { pa.has_seed = true; });
  };

  CLI::App* run_cmd = app.add_subcommand("run", "run a pipeline");
  add_pipeline_args(run_cmd);
  out.push_back({run_cmd, [] { return run(pa); }});

  static bool mermaid = false;
  CLI::App* graph_cmd = app.add_subcommand("graph", "validate a pipeline and print its stage graph");
  add_pipeline_args(graph_cmd);
  graph_cmd->add_flag("--mermaid", mermaid, "print a mermaid flowchart instead");
  out.push_back({graph_cmd, [] { return graph(pa, mermaid); }});

  static std::string kind;
  static bool json = false;
  CLI::App* plugins_cmd = app.add_subcommand("plugins", "list every registered stage with its parameters");
  plugins_cmd->add_option("--kind", kind, "only stages of this kind (e.g. encoder)");
  plugins_cmd->add_flag("--json", json, "machine-readable output");
  out.push_back({plugins_cmd, [] { return plugins(kind, json); }});

  CLI::App* info_cmd = app.add_subcommand("info", "version, BLAS library and kernel, threads, plug-in folders");
  out.push_back({info_cmd, [] { return info(); }});

  static int size = 2048, repeats = 10;
  CLI::App* bench = app.add_subcommand("bench", "benchmarks");
  bench->require_subcommand(1);
  CLI::App* blas = bench->add_subcommand("blas", "float32 matrix product through libtorch: GFLOP/s");
  blas->add_option("--size", size, "matrix size n (n x n)")->check(CLI::PositiveNumber);
  blas->add_option("--repeats", repeats, "timed repetitions")->check(CLI::PositiveNumber);
  out.push_back({blas, [] { return bench_blas(size, repeats); }, false});
}

}  // namespace bimart::cli
