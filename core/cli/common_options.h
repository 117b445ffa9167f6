// The conventions every `bimart` command shares (docs/cli.md): exit codes; -v/--verbose,
// -q/--quiet and --threads, accepted before or after the sub-command with one meaning;
// one rule for --seed; and the parse-and-run loop that main() calls.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <functional>
#include <string>

#include "core/cli/command.h"

namespace bimart::cli {

enum ExitCode : int {
  kExitOk = 0,
  kExitUserError = 1,    // bad input, bad flag, a file that cannot be read or written
  kExitInternal = 2,     // a bug or the machine (out of memory): please report
  kExitInterrupted = 130,  // Ctrl-C (SIGINT); SIGTERM gives 143
};

struct CommonOptions {
  int verbose = 0;
  int quiet = 0;
  int threads = 0;  // 0: all cores; at most max_threads() (core/util/parallel.h)
};
CommonOptions& common_options();

// Adds -v/--verbose, -q/--quiet and --threads to `app`, skipping any it already has.
void add_common_options(CLI::App* app);

// --seed: a whole number in [0, 2^64 - 1], written in digits; "-1", "1e23", "2^64" and
// the like are refused (CLI11 alone would wrap or clamp them).
CLI::Option* add_seed_option(CLI::App* app, std::uint64_t& seed, const std::string& help);

// Parses, applies the common options, runs the chosen command; maps every outcome to an
// exit code (parse errors and bimart::Error: 1; anything else: 2). `before_run(command)`
// runs after parsing and before the command (e.g. to load plug-ins).
int run_commands(CLI::App& app, const Commands& commands, int argc, char** argv,
                 const std::function<void(const Command&)>& before_run);

}  // namespace bimart::cli
