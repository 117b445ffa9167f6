// motion.ground_truth: the keypoints X of known hands (e.g. trajectory.sequence's ground
// truth), exact or corrupted as a diffusion model errs (core/synth/keypoint_corruption.h).
// It stands where motion.diffusion will, so the refinement and exporters can be run and
// measured before the generator exists; it ignores the object features it is wired to.
#include "core/features/hand_features.h"
#include "core/metrics/hand_vertices.h"
#include "core/pipeline/plugin.h"
#include "core/synth/keypoint_corruption.h"
#include "stages/motion_generator.h"

namespace bimart {
namespace {

class GroundTruthMotion : public MotionGenerator {
 public:
  static StageSpec spec() {
    KeypointCorruption d;
    return StageSpec::of<MotionGenerator>("ground_truth", "keypoints of known hands, optionally corrupted (for testing)")
        .input<HandMotion>("ground_truth", "the hands, world frame")
        .input<ArticulatedObject>("object", "the object, canonical frame")
        .input<at::Tensor>("object_states", "[N, 7]")
        .input<double>("fps", "frames per second")
        .param("corrupt", true, "add a diffusion model's typical errors (false: exact keypoints)")
        .param("noise", d.noise, "m, RMS error per keypoint and direction vector")
        .param("jitter", d.jitter, "m, RMS per-frame offset of each hand")
        .param("shift_min", d.shift_min, "m, shortest shift into the object")
        .param("shift_max", d.shift_max, "m, longest shift into the object")
        .param("stretches_per_second", d.stretches_per_second, "shifted stretches per hand and second")
        .param("seed", std::int64_t{1}, "corruption seed");
  }
  explicit GroundTruthMotion(const Params& p) : corrupt_(p.boolean("corrupt")), seed_(p.integer("seed")) {
    c_.noise = p.number("noise");
    c_.jitter = p.number("jitter");
    c_.shift_min = p.number("shift_min");
    c_.shift_max = p.number("shift_max");
    c_.stretches_per_second = p.number("stretches_per_second");
    c_.validate();
  }
  void run(StageIO& io) override {
    const at::Tensor& states = io.in<at::Tensor>("object_states");
    const HandMotion& truth = io.in<HandMotion>("ground_truth");
    // The keypoints as posed for the metrics ([2, N, 100, 3]), given as "vertices" 0..99.
    std::vector<int> ids(kHandKeypoints);
    for (int k = 0; k < kHandKeypoints; ++k) ids[static_cast<size_t>(k)] = k;
    at::Tensor X = hand_features(hand_keypoints(truth), ids, io.in<ArticulatedObject>("object"), states);
    if (corrupt_) X = corrupt_hand_features(X, io.in<double>("fps"), c_, static_cast<std::uint64_t>(seed_));
    io.out("hand_keypoints", X);
  }

 private:
  bool corrupt_;
  std::int64_t seed_;
  KeypointCorruption c_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::GroundTruthMotion)
