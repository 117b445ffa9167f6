// bimart data stats: opens a data set's train split with the training data loader
// (core/data/window_dataset.h), prints its windows, frames and memory, and writes the
// per-feature normalisation statistics (core/data/normalization.h).
#pragma once

#include <CLI/CLI.hpp>

#include "core/cli/command.h"

namespace bimart::cli {

// Adds `stats` under `data` (the `bimart data` sub-command, core/cli/data_commands.cc).
void add_data_stats_command(CLI::App& data, Commands& out);

}  // namespace bimart::cli
