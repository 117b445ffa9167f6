// trajectory.hinge_sweep: a complete third-party stage. A box with a lid that opens from
// one hinge angle to another with a smooth (minimum-jerk) profile while standing still.
#include <ATen/ATen.h>

#include <bimart/core/pipeline/plugin.h>
#include <bimart/stages/trajectory_source.h>

namespace {

class HingeSweep : public bimart::TrajectorySource {
 public:
  static bimart::StageSpec spec() {
    return bimart::StageSpec::of<bimart::TrajectorySource>("hinge_sweep",
                                                           "a box whose lid opens smoothly")
        .param("frames", 90, "number of frames (>= 2)")
        .param("fps", 30.0, "frames per second")
        .param("from", 0.0, "hinge angle at the first frame (rad)")
        .param("to", 1.2, "hinge angle at the last frame (rad)");
  }

  explicit HingeSweep(const bimart::Params& p)
      : frames_(p.integer("frames")), fps_(p.number("fps")), from_(p.number("from")), to_(p.number("to")) {
    if (frames_ < 2) throw bimart::Error("frames must be at least 2");
    if (!(fps_ > 0)) throw bimart::Error("fps must be positive");
  }

  void run(bimart::StageIO& io) override {
    at::Tensor states = at::zeros({frames_, 7}, at::kFloat);
    for (std::int64_t t = 0; t < frames_; ++t) {
      const double s = static_cast<double>(t) / static_cast<double>(frames_ - 1);
      const double smooth = s * s * s * (10 - 15 * s + 6 * s * s);  // minimum jerk
      states[t][0] = from_ + (to_ - from_) * smooth;
    }
    bimart::ArticulatedObject object;
    object.name = "example_box";
    object.bottom = bimart::make_box({0.0, -0.06, -0.1}, {0.25, 0.0, 0.1});
    object.top = bimart::make_box({0.0, 0.0, -0.1}, {0.25, 0.015, 0.1});
    io.out("object", std::move(object));
    io.out("object_states", states);
    io.out("fps", fps_);
  }

 private:
  std::int64_t frames_;
  double fps_, from_, to_;
};

}  // namespace

BIMART_REGISTER_STAGE(HingeSweep)
