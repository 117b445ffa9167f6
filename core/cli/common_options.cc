#include "core/cli/common_options.h"

#include <fmt/format.h>

#include <cctype>
#include <iostream>
#include <new>

#include "core/runtime/blas.h"
#include "core/util/error.h"
#include "core/util/interrupt.h"
#include "core/util/log.h"
#include "core/util/parallel.h"
#include "core/util/progress.h"
#include "core/util/text.h"

namespace bimart::cli {

CommonOptions& common_options() {
  static CommonOptions o;
  return o;
}

void add_common_options(CLI::App* app) {
  CommonOptions& o = common_options();
  auto has = [&](const char* name) { return app->get_option_no_throw(name) != nullptr; };
  if (!has("--verbose") && !has("-v")) app->add_flag("-v,--verbose", o.verbose, "more log output (debug)");
  if (!has("--quiet") && !has("-q"))
    app->add_flag("-q,--quiet", o.quiet, "only warnings and errors: no progress bars, no info lines");
  if (!has("--threads"))
    app->add_option("--threads", o.threads,
                    fmt::format("compute threads (default: all cores; 0 = all cores; at most 4 x cores = {})",
                                max_threads()))
        ->check(CLI::Range(0, max_threads()));
}

CLI::Option* add_seed_option(CLI::App* app, std::uint64_t& seed, const std::string& help) {
  const CLI::Validator digits(
      [](std::string& s) -> std::string {
        const bool all_digits = !s.empty() && s.size() <= 20 &&
                                std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
        if (all_digits) {
          errno = 0;
          char* end = nullptr;
          std::strtoull(s.c_str(), &end, 10);
          if (errno == 0 && *end == '\0') return "";
        }
        return "seed must be a whole number from 0 to 18446744073709551615, written in digits; got '" + s + "'";
      },
      "UINT64");
  return app
      ->add_option_function<std::string>(
          "--seed", [&seed](const std::string& s) { seed = std::strtoull(s.c_str(), nullptr, 10); }, help)
      ->check(digits);
}

namespace {

// The deepest sub-command that was chosen.
const CLI::App* chosen(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands())
    if (sub->parsed()) return chosen(*sub);
  return &app;
}

// "unknown command 'x'" with the closest names, when a word where a sub-command belongs
// matched none; "" otherwise.
std::string unknown_command(const CLI::App& app) {
  const CLI::App* at = chosen(app);
  if (at->get_require_subcommand_min() == 0) return "";
  std::vector<std::string> names;
  for (const CLI::App* sub : at->get_subcommands({})) names.push_back(sub->get_name());
  for (const std::string& word : at->remaining()) {
    if (word.empty() || word[0] == '-') continue;
    const std::string path = at == &app ? at->get_name() : at->get_parent()->get_name() + " " + at->get_name();
    return fmt::format("unknown command '{}'{}; `{} --help` lists: {}", word, did_you_mean(word, names), path,
                       join(names, ", "));
  }
  return "";
}

}  // namespace

int run_commands(CLI::App& app, const Commands& commands, int argc, char** argv,
                 const std::function<void(const Command&)>& before_run) {
  install_interrupt_handlers();
  add_common_options(&app);
  for (const Command& c : commands) add_common_options(c.app);
  app.allow_extras(false);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    const std::string unknown = unknown_command(app);
    if (!unknown.empty()) {
      std::cerr << "error: " << unknown << "\n";
      return kExitUserError;
    }
    app.exit(e);
    return kExitUserError;
  }
  const CommonOptions& o = common_options();
  log::setup(o.verbose - o.quiet);
  set_progress_enabled(o.quiet == 0);
  try {
    set_default_threads(o.threads);
    if (o.threads > 0) runtime::set_threads(o.threads);
    for (const Command& c : commands) {
      if (!c.app->parsed()) continue;
      if (before_run) before_run(c);
      return c.run();
    }
  } catch (const Error& e) {
    log::error("{}", e.what());
    return kExitUserError;
  } catch (const std::bad_alloc&) {
    log::error("out of memory (an input asked for more than this machine has; see the sizes in the command's input)");
    return kExitInternal;
  } catch (const std::exception& e) {
    log::error("internal error (please report): {}", e.what());
    return kExitInternal;
  }
  return kExitOk;
}

}  // namespace bimart::cli
