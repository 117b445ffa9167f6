// refine.mano_fit: MANO-layout hands fitted to the generated keypoints H (paper eq. 8):
// θ per frame and β per sequence for each hand, by Ceres (core/refine/mano_fit.h).
#include <fmt/format.h>

#include "core/features/hand_features.h"
#include "core/pipeline/plugin.h"
#include "core/refine/mano_fit.h"
#include "core/util/log.h"
#include "hand_models.h"
#include "samples.h"
#include "stages/refiner.h"

namespace bimart {
namespace {

class ManoFitStage : public Refiner {
 public:
  static StageSpec spec() {
    ManoFitOptions d;
    StageSpec s = StageSpec::of<Refiner>("mano_fit", "fit MANO (θ per frame, β per sequence) to the keypoints H with Ceres")
                      .param("w_pose", d.w_pose, "weak prior towards MANO's mean finger pose")
                      .param("w_shape", d.w_shape, "weak prior towards β = 0")
                      .param("w_smooth", d.w_smooth, "temporal smoothness: first differences of θ")
                      .param("w_limits", d.w_limits, "anatomical finger-joint limits (0: off)")
                      .param("w_fingers", d.w_fingers,
                             "fingers side by side: index, middle, ring, pinky in order across the hand (0: off)")
                      .param("finger_gap", d.finger_gap, "m, the least lateral gap between neighbouring fingers")
                      .param("w_separation", d.w_separation,
                             "fingers apart: two fingers' bones at least separation_gap apart (0: off)")
                      .param("separation_gap", d.separation_gap, "m, the least distance between two fingers' bone axes")
                      .param("fit_shape", d.fit_shape, "fit β (false: β = 0)")
                      .param("warm_start_iterations", d.warm_start_iterations, "solver steps per frame, frame by frame")
                      .param("max_iterations", d.max_iterations, "solver steps of the joint solve over all frames")
                      .param("threads", d.threads, "0: all cores (one hand per thread)");
    refine_plugin::declare_hand_params(s);
    return s;
  }

  explicit ManoFitStage(const Params& p) : hands_(refine_plugin::load_hand_pair(p)) {
    o_.w_pose = p.number("w_pose");
    o_.w_shape = p.number("w_shape");
    o_.w_smooth = p.number("w_smooth");
    o_.w_limits = p.number("w_limits");
    o_.w_fingers = p.number("w_fingers");
    o_.finger_gap = p.number("finger_gap");
    o_.w_separation = p.number("w_separation");
    o_.separation_gap = p.number("separation_gap");
    o_.fit_shape = p.boolean("fit_shape");
    o_.warm_start_iterations = static_cast<int>(p.integer("warm_start_iterations"));
    o_.max_iterations = static_cast<int>(p.integer("max_iterations"));
    o_.threads = static_cast<int>(p.integer("threads"));
    o_.validate();
  }

  void run(StageIO& io) override {
    const at::Tensor& states = io.in<at::Tensor>("object_states");
    refine_plugin::refine_samples(io, o_.threads, [&](std::size_t k, const at::Tensor& X, const HandMotion*, int threads) {
      ManoFitOptions o = o_;
      o.threads = threads;
      ManoFitReport report;
      HandMotion motion = fit_mano(hands_->pointers(), hand_features_to_world(X, states).positions, o, &report);
      log::info("mano_fit: {} frames, mean keypoint error {:.2f} / {:.2f} mm (left / right), {:.2f} s (sample {})",
                X.size(0), 1e3 * report.hands[0].mean_keypoint_error, 1e3 * report.hands[1].mean_keypoint_error,
                report.seconds, k);
      return motion;
    });
  }

 private:
  std::shared_ptr<const refine_plugin::HandPair> hands_;
  ManoFitOptions o_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::ManoFitStage)
