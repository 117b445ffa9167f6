// Logging: thin names over spdlog so call sites read `log::info("...", x)`.
#pragma once

#include <spdlog/spdlog.h>

namespace bimart::log {

using spdlog::debug;
using spdlog::error;
using spdlog::info;
using spdlog::warn;

// -v: debug, default: info, -q: warnings and errors only. Logs go to stderr.
void setup(int verbosity);

}  // namespace bimart::log
