// The CAMS-B baseline (paper §4 "Baselines", Table 1; docs/baselines.md): CAMS (Zheng et
// al., CVPR 2023) adapted to two hands and any category, in two stages.
//   contact.cams_b  a contact target per manipulation stage (manipulation_stages.h): the
//                   contact maps are generated from the object features (the contact
//                   diffusion model), then each stage holds its middle frame's map — which
//                   part, where on it, for each hand — in the object's canonical frame.
//   motion.cams_b   hands placed at each stage's target by the grasp planner, held on their
//                   part, blended between stages (stage_grasps.h); refine.ceres after it
//                   fits them against the object over time.
// What CAMS has and this has not: a per-category canonical manipulation space and a CVAE
// trained per category for the targets (here one contact model for every category), and
// per-finger targets with their own optimisation (here the planner's grasp at the target).
#include <chrono>
#include <memory>

#include "core/diffusion/model_kind.h"
#include "core/pipeline/plugin.h"
#include "core/util/log.h"
#include "manipulation_stages.h"
#include "plugins/diffusion/mano_samples.h"
#include "plugins/diffusion/model_params.h"
#include "stage_grasps.h"
#include "stages/contact_generator.h"
#include "stages/motion_generator.h"

namespace bimart {
namespace {

class CamsTargets : public ContactGenerator {
 public:
  static StageSpec spec() {
    StageSpec s = StageSpec::of<ContactGenerator>(
        "cams_b", "CAMS-B: one contact target per manipulation stage, from the contact model's maps");
    diffusion_plugin::declare_sampling_params(s, "models/contact.npz");
    s.param("min_stage", 8, "frames: a shorter run of still / moved / articulated frames joins the stage before")
        .input<at::Tensor>("object_states", "[N, 7]: what the object does decides the stages")
        .output<at::Tensor>("contact_maps_samples", "[S, N, 2, 1024]: every sample's stage-wise targets")
        .output<at::Tensor>("manipulation_stages", "[K, 3] int64: first frame, last frame, what (0 still, 1 moved, 2 articulated)");
    return s;
  }

  explicit CamsTargets(const Params& p) : s_(diffusion_plugin::read_sampling_params(p)), min_stage_(p.integer("min_stage")) {
    if (min_stage_ < 1) throw Error("'min_stage' must be >= 1 frame, got " + std::to_string(min_stage_));
    diffusion::check_sampling_stage(s_.model->info(), s_.model->path(), "contact.diffusion");
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    diffusion_plugin::check_encoder(*s_.model, io);
    const auto stages = manipulation_stages(io.in<at::Tensor>("object_states"), min_stage_);
    const at::Tensor C = s_.model->generate(io.in<at::Tensor>("object_features"), io.in<at::Tensor>("global_states"),
                                            {}, nullptr, s_.options, diffusion_plugin::stage_generator(io));
    const at::Tensor targets = stage_contact_targets(C, stages);
    log::info("contact.cams_b: {} stages over {} frames x {} samples in {:.2f} s", stages.size(), C.size(1), C.size(0),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    io.out("contact_maps", targets[0].contiguous());
    io.out("contact_maps_samples", targets);
    io.out("manipulation_stages", stages_tensor(stages));
  }

 private:
  diffusion_plugin::Sampling s_;
  std::int64_t min_stage_;
};

class CamsHands : public MotionGenerator {
 public:
  static StageSpec spec() {
    StageGraspOptions d;
    StageSpec s = StageSpec::of<MotionGenerator>(
        "cams_b", "CAMS-B: hands placed at each manipulation stage's contact target (grasp planner), held, blended");
    s.param("samples", 1, "samples: one set of hands per target sample (as many as contact.cams_b drew)")
        .param("contact", d.contact, "m: a target point below this is a contact point")
        .param("site_radius", d.site_radius, "m: the grasp site within this of the contact points' centre")
        .param("blend", static_cast<std::int64_t>(d.blend), "frames over which one stage's grasp turns into the next's")
        .param("max_depth", d.max_depth, "m: the planner's deepest hand vertex")
        .input<at::Tensor>("manipulation_stages", "[K, 3] int64 (contact.cams_b)")
        .optional_input<at::Tensor>("contact_maps_samples", "[S, N, 2, 1024]: one stage-wise target per sample")
        .input<at::Tensor>("basis_hit_indices", "[N, 1024] int64: the object vertex of each target row");
    diffusion_plugin::declare_mano_hands(s);
    return s;
  }

  explicit CamsHands(const Params& p) : hands_(p), samples_(p.integer("samples")) {
    o_.contact = p.number("contact");
    o_.site_radius = p.number("site_radius");
    o_.blend = p.integer("blend");
    o_.max_depth = p.number("max_depth");
    if (samples_ < 1 || samples_ > 1024) throw Error("'samples' must be in [1, 1024]");
    if (!(o_.contact > 0) || !(o_.site_radius > 0) || o_.blend < 0 || !(o_.max_depth > 0))
      throw Error("'contact', 'site_radius' and 'max_depth' must be > 0 (m), 'blend' >= 0 (frames)");
  }

  void run(StageIO& io) override {
    const auto t0 = std::chrono::steady_clock::now();
    if (!io.has("contact_maps")) throw Error("motion.cams_b needs the stage-wise contact targets (contact.cams_b)");
    const ArticulatedObject& object = io.in<ArticulatedObject>("object");
    const at::Tensor& states = io.in<at::Tensor>("object_states");
    const auto stages = stages_from_tensor(io.in<at::Tensor>("manipulation_stages"));
    const bool each = io.has("contact_maps_samples") && io.in<at::Tensor>("contact_maps_samples").size(0) == samples_;
    const ObjectDistance distance(object);
    const auto models = hands_.hands().pointers();
    std::vector<HandMotion> hands;
    for (std::int64_t k = 0; k < samples_; ++k) {
      const at::Tensor targets = each ? io.in<at::Tensor>("contact_maps_samples")[k] : io.in<at::Tensor>("contact_maps");
      hands.push_back(stage_grasp_hands(object, distance, models, states, targets,
                                        io.in<at::Tensor>("basis_hit_indices"), stages, o_, io.rng()()));
    }
    hands_.write_hands(io, std::move(hands));
    log::info("motion.cams_b: {} stages, {} frames x {} samples in {:.2f} s", stages.size(), states.size(0), samples_,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }

 private:
  diffusion_plugin::ManoHands hands_;
  std::int64_t samples_;
  StageGraspOptions o_;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::CamsTargets)
BIMART_REGISTER_STAGE(bimart::CamsHands)
