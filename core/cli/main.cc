// bimart: the command-line program. Sub-commands live in commands.cc.
#include <CLI/CLI.hpp>

#include <iostream>

#include "core/cli/commands.h"
#include "core/runtime/blas.h"
#include "core/util/error.h"
#include "core/util/log.h"

int main(int argc, char** argv) {
  // May re-execute the program once with the right OpenBLAS kernel (DESIGN §8).
  bimart::runtime::ensure_blas_kernel(argc, argv);

  CLI::App app{"bimart: bimanual hand motion for articulated objects", "bimart"};
  app.require_subcommand(1);
  app.set_version_flag("--version", [] { return bimart::cli::version_text(); });
  int verbose = 0, quiet = 0, threads = 0;
  std::vector<std::string> plugin_libs;
  app.add_flag("-v,--verbose", verbose, "more log output (debug)");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");
  app.add_option("--threads", threads, "threads for libtorch and BLAS (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--plugin", plugin_libs, "extra plug-in library to load (repeatable)")
      ->check(CLI::ExistingFile);

  bimart::cli::PipelineArgs pa;
  auto add_pipeline_args = [&](CLI::App* cmd) {
    cmd->add_option("pipeline", pa.pipeline, "pipeline YAML file")->required()->check(CLI::ExistingFile);
    cmd->add_option("--set", pa.overrides, "override a parameter: stage.param=value (repeatable)");
    cmd->add_option("--seed", pa.seed, "override the pipeline's seed")->check(CLI::NonNegativeNumber);
  };

  CLI::App* run = app.add_subcommand("run", "run a pipeline");
  add_pipeline_args(run);

  bool mermaid = false;
  CLI::App* graph = app.add_subcommand("graph", "validate a pipeline and print its stage graph");
  add_pipeline_args(graph);
  graph->add_flag("--mermaid", mermaid, "print a mermaid flowchart instead");

  std::string kind;
  bool json = false;
  CLI::App* plugins = app.add_subcommand("plugins", "list every registered stage with its parameters");
  plugins->add_option("--kind", kind, "only stages of this kind (e.g. encoder)");
  plugins->add_flag("--json", json, "machine-readable output");

  CLI::App* info = app.add_subcommand("info", "version, BLAS library and kernel, threads, plug-in folders");

  int size = 2048, repeats = 10;
  CLI::App* bench = app.add_subcommand("bench", "benchmarks");
  bench->require_subcommand(1);
  CLI::App* bench_blas = bench->add_subcommand("blas", "float32 matrix product through libtorch: GFLOP/s");
  bench_blas->add_option("--size", size, "matrix size n (n x n)")->check(CLI::PositiveNumber);
  bench_blas->add_option("--repeats", repeats, "timed repetitions")->check(CLI::PositiveNumber);

  CLI11_PARSE(app, argc, argv);

  bimart::log::setup(verbose - quiet);
  try {
    bimart::runtime::set_threads(threads);
    if (*bench) return bimart::cli::bench_blas(size, repeats);
    bimart::cli::load_plugins(plugin_libs);
    if (*run) return bimart::cli::run(pa);
    if (*graph) return bimart::cli::graph(pa, mermaid);
    if (*plugins) return bimart::cli::plugins(kind, json);
    if (*info) return bimart::cli::info();
  } catch (const bimart::Error& e) {
    bimart::log::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    bimart::log::error("unexpected error: {}", e.what());
    return 2;
  }
  return 0;
}
