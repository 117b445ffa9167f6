// export.states_csv: writes object states as CSV (frame, time, 7 state numbers).
#include <ATen/ATen.h>

#include <iomanip>

#include "core/pipeline/plugin.h"
#include "core/util/atomic_file.h"
#include "stages/exporter.h"

namespace bimart {
namespace {

class StatesCsv : public Exporter {
 public:
  static StageSpec spec() {
    return StageSpec::of<Exporter>("states_csv", "object states as CSV, one row per frame")
        .input<at::Tensor>("object_states", "[N, 7] object states")
        .input<double>("fps", "frames per second")
        .param("path", "out/states.csv", "file to write (folders are created)");
  }

  explicit StatesCsv(const Params& p) : path_(p.string("path")) {
    if (path_.empty()) throw Error("path must not be empty");
  }

  void run(StageIO& io) override {
    const at::Tensor& states = io.in<at::Tensor>("object_states");
    const double fps = io.in<double>("fps");
    if (states.dim() != 2 || states.size(1) != 7)
      throw Error("object_states must be [N, 7], got " + std::string(c10::str(states.sizes())));
    const at::Tensor s = states.to(at::kDouble).contiguous();
    const auto a = s.accessor<double, 2>();
    write_file_atomically(path_, [&](std::ostream& out) {
      out << "frame,time,angle,rx,ry,rz,tx,ty,tz\n" << std::setprecision(9);
      for (std::int64_t t = 0; t < s.size(0); ++t) {
        out << t << ',' << t / fps;
        for (int k = 0; k < 7; ++k) out << ',' << a[t][k];
        out << '\n';
      }
    });
    io.out("path", path_);
  }

 private:
  std::string path_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::StatesCsv)
