// bimart: the command-line program. Each core/cli/*_commands.cc adds its sub-commands.
#include <CLI/CLI.hpp>

#include <iostream>

#include "core/cli/command.h"
#include "core/cli/pipeline_commands.h"
#include "core/runtime/allocator.h"
#include "core/runtime/blas.h"
#include "core/util/error.h"
#include "core/util/log.h"

int main(int argc, char** argv) {
  // May re-execute the program once with the right OpenBLAS kernel (DESIGN §8).
  bimart::runtime::ensure_blas_kernel(argc, argv);
  bimart::runtime::tune_allocator();

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

  bimart::cli::Commands commands;
  bimart::cli::add_pipeline_commands(app, commands);
  bimart::cli::add_bps_commands(app, commands);
  bimart::cli::add_object_commands(app, commands);
  bimart::cli::add_hand_commands(app, commands);
  bimart::cli::add_eval_commands(app, commands);
  bimart::cli::add_data_commands(app, commands);
  bimart::cli::add_refine_commands(app, commands);
  bimart::cli::add_train_commands(app, commands);
  bimart::cli::add_generate_commands(app, commands);
  bimart::cli::add_export_commands(app, commands);

  bimart::runtime::set_threads(0);  // all cores, also for what --version reports
  CLI11_PARSE(app, argc, argv);

  bimart::log::setup(verbose - quiet);
  try {
    if (threads > 0) bimart::runtime::set_threads(threads);
    for (const auto& c : commands) {
      if (!c.app->parsed()) continue;
      if (c.needs_plugins) bimart::cli::load_plugins(plugin_libs);
      return c.run();
    }
  } catch (const bimart::Error& e) {
    bimart::log::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    bimart::log::error("unexpected error: {}", e.what());
    return 2;
  }
  return 0;
}
