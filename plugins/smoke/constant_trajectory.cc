// trajectory.constant: a small box with a lid held at one 7-DoF state for N frames, with
// optional seeded noise. Proves the wiring end to end until real trajectory sources land.
#include <ATen/ATen.h>

#include <random>

#include "core/io/sequence.h"
#include "core/pipeline/plugin.h"
#include "stages/trajectory_source.h"

namespace bimart {
namespace {

class ConstantTrajectory : public TrajectorySource {
 public:
  static StageSpec spec() {
    return StageSpec::of<TrajectorySource>("constant", "a box with a lid held at one state, with optional noise")
        .param("frames", 64, "number of frames (1 .. 1000000)")
        .param("fps", 30.0, "frames per second (> 0)")
        .param("angle", 0.0, "hinge angle (rad)")
        .param("rotation", std::vector<double>{0, 0, 0}, "root axis-angle (rad)")
        .param("translation", std::vector<double>{0, 0, 0}, "root translation (m)")
        .param("noise", 0.0, "std. dev. of Gaussian noise added to every state number (0: constant)");
  }

  explicit ConstantTrajectory(const Params& p)
      : frames_(p.integer("frames")),
        fps_(p.number("fps")),
        noise_(p.number("noise")),
        state_{p.number("angle")} {
    if (frames_ < 1 || frames_ > kMaxFrames)
      throw Error("frames must be at least 1 and at most " + std::to_string(kMaxFrames) + ", got " +
                  std::to_string(frames_));
    if (!(fps_ > 0)) throw Error("fps must be positive, got " + std::to_string(fps_));
    if (!(noise_ >= 0)) throw Error("noise must be >= 0, got " + std::to_string(noise_));
    for (const char* name : {"rotation", "translation"}) {
      const auto& v = p.numbers(name);
      if (v.size() != 3)
        throw Error(std::string(name) + " needs 3 numbers, got " + std::to_string(v.size()));
      state_.insert(state_.end(), v.begin(), v.end());
    }
  }

  void run(StageIO& io) override {
    at::Tensor states = at::empty({frames_, 7}, at::kFloat);
    auto a = states.accessor<float, 2>();
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (std::int64_t t = 0; t < frames_; ++t)
      for (int k = 0; k < 7; ++k)
        a[t][k] = static_cast<float>(state_[k] + (noise_ > 0 ? noise_ * gauss(io.rng()) : 0.0));

    ArticulatedObject object;
    object.name = "smoke_box";
    // Hinge along z through the origin; the lid lies on top of the base along +y.
    object.bottom = make_box({0.0, -0.05, -0.1}, {0.2, 0.0, 0.1});
    object.top = make_box({0.0, 0.0, -0.1}, {0.2, 0.02, 0.1});

    io.out("object", std::move(object));
    io.out("object_states", states);
    io.out("fps", fps_);
  }

 private:
  std::int64_t frames_;
  double fps_;
  double noise_;
  std::vector<double> state_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::ConstantTrajectory)
