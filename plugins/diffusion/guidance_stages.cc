// guidance.contact_map (DESIGN §5, core/diffusion/contact_guidance.h) and guidance.none.
#include <ATen/ATen.h>

#include <memory>
#include <tuple>

#include "core/diffusion/contact_guidance.h"
#include "core/diffusion/contact_support.h"
#include "core/directing/contact_rules.h"
#include "core/features/contact_map.h"
#include "core/pipeline/plugin.h"
#include "stages/guidance.h"

namespace bimart {
namespace {

class ContactMapGuidanceStage : public GuidanceStage {
 public:
  static StageSpec spec() {
    const diffusion::PlacementOptions d;
    return StageSpec::of<GuidanceStage>("contact_map",
                                        "pulls the keypoints' contact map onto C at every diffusion step")
        .param("scale", 1.0, "norm of the correction per sample (λ_c = scale / ||∇||); 0 = off")
        .param("release_steps", 0,
               "no correction at the last this many steps, so the denoiser re-forms the hands (ours; 0 = the paper's)")
        .param("place_steps", 0,
               "also translate each hand onto its contacts at the last this many steps (ours; 0 = the paper's)")
        .param("place_threshold", d.threshold, "m: object points with C below this are contacts (placement)")
        .param("place_sigma", d.sigma, "frames: smoothing of the placement's translations over time")
        .param("place_iterations", d.iterations, "ICP rounds of the placement")
        .param("place_snap", d.snap,
               "m: a hand whose map's minimum is below this (not touching per place_threshold) is placed where its "
               "map is smallest (0 = off)")
        .param("place_depth", d.depth, "m: place keypoints this much closer to (> 0: into) the object than C says")
        .param("hold", false,
               "frames where the object moves (the hinge turns) with no hand's map touching it (its top part): "
               "the nearest hand is read as touching where its map is smallest (ours; core/diffusion/contact_support.h)")
        .param("hold_place", false,
               "with the placement: where the object moves (the hinge turns) and no hand's keypoints come within "
               "place_threshold of it (its top part), the nearest hand is moved onto it (ours; core/diffusion/contact_support.h)")
        .optional_input<at::Tensor>("contact_maps_samples", "[S, N, 2, 1024]: one target per sample")
        .optional_input<HandConstraints>("hand_constraints",
                                         "hold and hold_place leave a hand where it must not touch (docs/directing.md), "
                                         "and the targets keep to the contact constraints");
  }
  explicit ContactMapGuidanceStage(const Params& p)
      : scale_(p.number("scale")), place_steps_(static_cast<int>(p.integer("place_steps"))),
        release_steps_(static_cast<int>(p.integer("release_steps"))), hold_(p.boolean("hold")),
        hold_place_(p.boolean("hold_place")) {
    if (!(scale_ >= 0)) throw Error("'scale' must not be negative");
    if (place_steps_ < 0) throw Error("'place_steps' must not be negative");
    if (release_steps_ < 0) throw Error("'release_steps' must not be negative");
    place_.threshold = p.number("place_threshold");
    place_.sigma = p.number("place_sigma");
    place_.iterations = static_cast<int>(p.integer("place_iterations"));
    place_.snap = p.number("place_snap");
    place_.depth = p.number("place_depth");
    place_.validate();
  }
  void run(StageIO& io) override {
    const auto& object = io.in<ArticulatedObject>("object");
    const auto& states = io.in<at::Tensor>("object_states");
    const auto& hits = io.in<at::Tensor>("basis_hit_indices");
    const at::Tensor points = basis_hit_points(object, states, hits);
    at::Tensor target = io.has("contact_maps_samples") ? io.in<at::Tensor>("contact_maps_samples")
                                                       : io.in<at::Tensor>("contact_maps").unsqueeze(0);
    const auto [held, turning] = held_frames(object, states);
    const at::Tensor top = hits < static_cast<std::int64_t>(object.top.num_vertices());
    const HandConstraints* directed = io.has("hand_constraints") ? &io.in<HandConstraints>("hand_constraints") : nullptr;
    at::Tensor may_hold, may_top;  // undefined: either hand
    if (directed) std::tie(may_hold, may_top) = hands_that_may_hold(*directed, states.size(0));
    if (hold_) target = diffusion::hold_contacts(target, held, turning, top, place_.threshold, may_hold, may_top);
    if (directed) target = ContactRules(*directed, object, hits).impose(target, 0, -1, 0);
    auto g = std::make_shared<diffusion::ContactMapGuidance>(points, target, scale_);
    g->set_placement(place_steps_, place_);
    g->set_release(release_steps_);
    if (hold_place_) g->set_support(held, turning, top, place_.threshold, may_hold, may_top);
    io.out("guidance", std::shared_ptr<const Guidance>(std::move(g)));
  }

 private:
  double scale_;
  int place_steps_, release_steps_;
  bool hold_, hold_place_;
  diffusion::PlacementOptions place_;
};

class NoGuidance : public Guidance {
 public:
  at::Tensor correction(const at::Tensor& x0, std::int64_t, int, int) const override { return at::zeros_like(x0); }
};

class NoGuidanceStage : public GuidanceStage {
 public:
  static StageSpec spec() { return StageSpec::of<GuidanceStage>("none", "no guidance (a zero correction)"); }
  explicit NoGuidanceStage(const Params&) {}
  void run(StageIO& io) override { io.out("guidance", std::shared_ptr<const Guidance>(std::make_shared<NoGuidance>())); }
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::ContactMapGuidanceStage)
BIMART_REGISTER_STAGE(bimart::NoGuidanceStage)
