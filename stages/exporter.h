// Stage kind "export": writes results to files. Each exporter declares the inputs it
// needs; all of them report where they wrote. Files are written to a temporary name and
// renamed, so a failed run never leaves a half-written output.
#pragma once

#include <string>

#include "core/pipeline/stage.h"

namespace bimart {

class Exporter : public Stage {
 public:
  static constexpr const char* kKind = "export";

  static void declare(StageSpec& s) {
    s.output<std::string>("path", "path of the file (or folder) written");
  }
};

}  // namespace bimart
