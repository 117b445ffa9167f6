// The OMOMO-B baseline (paper §4 "Baselines" and Sup. C; docs/baselines.md), OMOMO (Li et
// al. 2023) adapted from a body carrying an object to two hands: two diffusion models.
//   joints.omomo_b  stage one: the 16 joint positions of both hands from the object features
//                   alone, with every joint that comes near the object put on its surface at
//                   each denoising step (joint_contact.h; OMOMO constrains its wrists so, the
//                   paper all hand joints).
//   motion.omomo_b  stage two: the hands (MANO representation, as MANO-Rep) from the object
//                   features and those joints, decoded by the hand model like
//                   motion.diffusion_mano's, so every stage after it runs unchanged.
// Trained with models/baselines/omomo_b_joints.yaml and omomo_b_hands.yaml; stage two is
// trained on the ground truth's joints (OMOMO trains its second stage so too).
#include <chrono>

#include "core/diffusion/model_kind.h"
#include "core/pipeline/plugin.h"
#include "core/util/log.h"
#include "joint_contact.h"
#include "joints_generator.h"
#include "plugins/diffusion/mano_samples.h"
#include "plugins/diffusion/model_params.h"
#include "stages/motion_generator.h"

namespace bimart {
namespace {

class OmomoJoints : public JointsGenerator {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<JointsGenerator>(
        "omomo_b", "OMOMO-B stage one: both hands' joints from the object features, joints near the object put on it");
    diffusion_plugin::declare_sampling_params(s, "models/baselines/omomo_b_joints.npz");
    s.param("contact_reach", 0.02, "metres: a joint closer than this to the object is put on its surface at every step")
        .input<ArticulatedObject>("object", "the two-part object (its surface for the contact constraint)")
        .input<at::Tensor>("object_states", "[N, 7] float32 (the hinge angle of each frame)");
    return s;
  }

  explicit OmomoJoints(const Params& p) : s_(diffusion_plugin::read_sampling_params(p)), reach_(p.number("contact_reach")) {
    s_.options.cfg_lambda = 0;
    s_.options.use_contact = false;
    if (!(reach_ >= 0)) throw Error("'contact_reach' must be >= 0 (metres), got " + std::to_string(reach_));
    diffusion::check_sampling_stage(s_.model->info(), s_.model->path(), "joints.omomo_b");
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    diffusion_plugin::check_encoder(*s_.model, io);
    const JointContact contact(io.in<ArticulatedObject>("object"), io.in<at::Tensor>("object_states"), reach_);
    const at::Tensor J = s_.model->generate(io.in<at::Tensor>("object_features"), io.in<at::Tensor>("global_states"),
                                            {}, nullptr, s_.options, diffusion_plugin::stage_generator(io), &contact);
    log::info("joints.omomo_b: {} frames x {} samples in {:.2f} s", J.size(1), J.size(0),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    io.out("hand_joints", J[0].contiguous());
    io.out("hand_joints_samples", J);
  }

 private:
  diffusion_plugin::Sampling s_;
  double reach_;
};

class OmomoHands : public MotionGenerator {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<MotionGenerator>(
        "omomo_b", "OMOMO-B stage two: MANO hands from the object features and both hands' joints");
    diffusion_plugin::declare_sampling_params(s, "models/baselines/omomo_b_hands.npz");
    s.input<at::Tensor>("hand_joints", "[N, 96]: the joints of stage one (joints.omomo_b), sample 0")
        .optional_input<at::Tensor>("hand_joints_samples",
                                    "[S, N, 96]: one set of joints per sample; used when it holds `samples` of them");
    diffusion_plugin::declare_mano_hands(s);
    return s;
  }

  explicit OmomoHands(const Params& p) : s_(diffusion_plugin::read_sampling_params(p)), hands_(p) {
    s_.options.cfg_lambda = 0;
    diffusion::check_sampling_stage(s_.model->info(), s_.model->path(), "motion.omomo_b");
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    diffusion_plugin::check_encoder(*s_.model, io);
    if (io.has("guidance"))
      throw Error("motion.omomo_b takes no guidance: OMOMO-B's contact constraint acts on the joints of stage one");
    const bool each = io.has("hand_joints_samples") && io.in<at::Tensor>("hand_joints_samples").size(0) == s_.options.samples;
    const at::Tensor joints = io.in<at::Tensor>(each ? "hand_joints_samples" : "hand_joints");
    const at::Tensor M = s_.model->generate(io.in<at::Tensor>("object_features"), io.in<at::Tensor>("global_states"),
                                            joints, nullptr, s_.options, diffusion_plugin::stage_generator(io));
    hands_.write(io, M, "motion.omomo_b", t0);
  }

 private:
  diffusion_plugin::Sampling s_;
  diffusion_plugin::ManoHands hands_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::OmomoJoints)
BIMART_REGISTER_STAGE(bimart::OmomoHands)
