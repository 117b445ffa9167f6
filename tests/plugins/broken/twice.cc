// Registers two classes under one key.
#include "core/pipeline/plugin.h"
#include "stages/exporter.h"

namespace {
template <int N>
class Same : public bimart::Exporter {
 public:
  static bimart::StageSpec spec() { return bimart::StageSpec::of<bimart::Exporter>("same_name", "twice"); }
  explicit Same(const bimart::Params&) {}
  void run(bimart::StageIO& io) override { io.out("path", std::to_string(N)); }
};
}  // namespace

BIMART_REGISTER_STAGE(Same<1>)
BIMART_REGISTER_STAGE(Same<2>)
