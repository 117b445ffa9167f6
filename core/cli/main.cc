// bimart: the command-line program. Each core/cli/*_commands.cc adds its sub-commands;
// the shared options, exit codes and error handling are in core/cli/common_options.h.
#include <CLI/CLI.hpp>

#include "core/cli/command.h"
#include "core/cli/common_options.h"
#include "core/cli/pipeline_commands.h"
#include "core/runtime/allocator.h"
#include "core/runtime/blas.h"

int main(int argc, char** argv) {
  // May re-execute the program once with the right OpenBLAS kernel (DESIGN §8).
  bimart::runtime::ensure_blas_kernel(argc, argv);
  bimart::runtime::tune_allocator();

  CLI::App app{"bimart: bimanual hand motion for articulated objects", "bimart"};
  app.require_subcommand(1);
  app.set_version_flag("--version", [] { return bimart::cli::version_text(); });
  std::vector<std::string> plugin_libs;
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
  bimart::cli::add_model_commands(app, commands);
  bimart::cli::add_sweep_commands(app, commands);
  bimart::cli::add_edit_commands(app, commands);

  bimart::runtime::set_threads(0);  // all cores, also for what --version reports
  return bimart::cli::run_commands(app, commands, argc, argv, [&](const bimart::cli::Command& c) {
    if (c.needs_plugins) bimart::cli::load_plugins(plugin_libs);
  });
}
