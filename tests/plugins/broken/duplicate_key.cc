// Claims trajectory.constant, which the built-in smoke library registers.
#include "core/pipeline/plugin.h"
#include "stages/exporter.h"

namespace {
class Impostor : public bimart::Exporter {
 public:
  static bimart::StageSpec spec() {
    bimart::StageSpec s("trajectory.constant", "an impostor");
    bimart::Exporter::declare(s);
    return s;
  }
  explicit Impostor(const bimart::Params&) {}
  void run(bimart::StageIO& io) override { io.out("path", std::string()); }
};
}  // namespace

BIMART_REGISTER_STAGE(Impostor)
