// A plug-in that links Ceres (and so, on Debian, ATLAS's libf77blas) and reports which
// library its own reference to sgemm_ was bound to when the host loaded it: the BLAS a
// plug-in's libtorch calls would reach (tests/plugins/plugin_loader_test.cc).
#include <dlfcn.h>

#include <climits>
#include <cstdlib>
#include <string>

#include <ceres/ceres.h>

#include "core/pipeline/plugin.h"
#include "stages/exporter.h"

// Weak, so the library loads even where no BLAS is linked; bound at load time.
extern "C" void sgemm_() __attribute__((weak));

extern "C" __attribute__((visibility("default"))) const char* bimart_test_sgemm_library() {
  static std::string file;
  Dl_info where{};
  void* symbol = reinterpret_cast<void*>(&sgemm_);
  if (symbol == nullptr || dladdr(symbol, &where) == 0 || where.dli_fname == nullptr) return "";
  char resolved[PATH_MAX];
  file = realpath(where.dli_fname, resolved) != nullptr ? resolved : where.dli_fname;
  return file.c_str();
}

namespace {
// Uses Ceres, so that the link keeps it (and its BLAS) among the library's dependencies.
class BlasProbe : public bimart::Exporter {
 public:
  static bimart::StageSpec spec() {
    return bimart::StageSpec::of<bimart::Exporter>("blas_probe", "reports the BLAS of a plug-in");
  }
  explicit BlasProbe(const bimart::Params&) {}
  void run(bimart::StageIO& io) override {
    ceres::Problem problem;
    io.out("path", std::string(bimart_test_sgemm_library()));
  }
};
}  // namespace

BIMART_REGISTER_STAGE(BlasProbe)
