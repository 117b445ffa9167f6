// Calls a function that no library defines, so the dynamic loader cannot resolve it.
#include "core/pipeline/plugin.h"
#include "stages/exporter.h"

extern "C" int bimart_test_function_that_does_not_exist(int);

namespace {
class Undefined : public bimart::Exporter {
 public:
  static bimart::StageSpec spec() { return bimart::StageSpec::of<bimart::Exporter>("undefined", "never loads"); }
  explicit Undefined(const bimart::Params&) {}
  void run(bimart::StageIO& io) override {
    io.out("path", std::to_string(bimart_test_function_that_does_not_exist(1)));
  }
};
}  // namespace

BIMART_REGISTER_STAGE(Undefined)
