#include "core/util/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>

namespace bimart::log {

void setup(int verbosity) {
  auto logger = spdlog::get("bimart");
  if (!logger) logger = spdlog::stderr_color_mt("bimart");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("[%H:%M:%S.%e] %^%l%$ %v");
  spdlog::set_level(verbosity > 0 ? spdlog::level::debug
                                  : verbosity < 0 ? spdlog::level::warn : spdlog::level::info);
}

}  // namespace bimart::log
