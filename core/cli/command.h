// How a sub-command plugs into `bimart`: a function that adds its CLI11 sub-command(s) and
// returns, for each, the handler to run when it was chosen. Handlers return the exit code
// and may throw bimart::Error (printed as an error, exit code 1).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace bimart::cli {

struct Command {
  CLI::App* app;
  std::function<int()> run;
  bool needs_plugins = true;  // load the plug-in libraries before running
};

using Commands = std::vector<Command>;

// One per file in core/cli/: each adds its sub-commands to `app`.
void add_pipeline_commands(CLI::App& app, Commands& out);  // run, graph, plugins, info, bench
void add_bps_commands(CLI::App& app, Commands& out);       // bps make
void add_object_commands(CLI::App& app, Commands& out);    // object make, list, info, gallery
void add_hand_commands(CLI::App& app, Commands& out);      // hand make
void add_eval_commands(CLI::App& app, Commands& out);      // eval
void add_data_commands(CLI::App& app, Commands& out);      // data synth, data stats
void add_refine_commands(CLI::App& app, Commands& out);    // refine
void add_train_commands(CLI::App& app, Commands& out);     // train
void add_generate_commands(CLI::App& app, Commands& out);  // generate
void add_export_commands(CLI::App& app, Commands& out);    // export, view, render
void add_model_commands(CLI::App& app, Commands& out);     // model check
void add_sweep_commands(CLI::App& app, Commands& out);     // sweep, sweep status
void add_edit_commands(CLI::App& app, Commands& out);      // edit
}  // namespace bimart::cli
