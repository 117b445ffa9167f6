// refine.ceres: the fitted hands refined against the object (paper eq. 9-12): projection
// of keypoints plus direction vectors onto the surface, penetration, acceleration, by
// Ceres with CGAL surface queries (core/refine/refinement.h). Starts from the previous
// refiner's hand_params (refine.mano_fit); without one it fits first, with defaults.
#include <ATen/ATen.h>
#include <fmt/format.h>

#include <optional>

#include "core/directing/refine_directions.h"
#include "core/io/sequence.h"
#include "core/features/hand_features.h"
#include "core/metrics/held_frames.h"
#include "core/object/object_distance.h"
#include "core/pipeline/plugin.h"
#include "core/refine/mano_fit.h"
#include "core/refine/refinement.h"
#include "core/util/log.h"
#include "hand_models.h"
#include "samples.h"
#include "stages/refiner.h"

namespace bimart {
namespace {

class CeresRefineStage : public Refiner {
 public:
  static StageSpec spec() {
    RefineOptions d;
    StageSpec s =
        StageSpec::of<Refiner>("ceres", "refine the hands against the object: projection, penetration, acceleration (Ceres, CGAL)")
            .param("w_proj", d.w_proj, "keypoint + predicted direction on the object surface (paper: 100)")
            .param("w_pen", d.w_pen, "hand vertices inside the object (paper: 10); grows per frame while too deep")
            .param("w_acc", d.w_acc, "second differences of hand vertices (paper: 1000)")
            .param("w_fit", d.w_fit, "keypoints near the prediction (ours)")
            .param("rounds", d.outer_iterations, "linearisations of the object surface")
            .param("steps", d.max_iterations, "solver steps per round")
            .param("max_rounds", d.max_outer_iterations, "rounds while a frame is deeper than pen_tolerance")
            .param("pen_margin", d.pen_margin, "m: vertices this close to the surface get a penetration plane")
            .param("pen_exit_depth", d.pen_exit_depth,
                   "m: frames deeper than this push inside vertices out towards the rest of the hand (1e9 = off)")
            .param("pen_exit_smooth", std::int64_t{d.pen_exit_smooth},
                   "frames: frames this near a deep one leave the way the deep ones there do on average (0: each its own)")
            .param("pen_cavities", d.pen_cavities,
                   "hand vertices in a hollow part's cavity behind a wall leave through it (ours; false: the paper's)")
            .param("pen_fingers_through", d.pen_fingers_through,
                   "a finger through a thin part comes back through it whole (ours; false: the paper's)")
            .param("pen_tolerance", d.pen_tolerance, "m: frames deeper than this get a larger penetration weight")
            .param("pen_growth", d.pen_growth, "factor of that growth per round")
            .param("max_pen_boost", d.max_pen_boost, "the largest that growth makes a frame's penetration weight (x w_pen)")
            .param("accel_vertices", d.accel_vertices, "hand vertices in the acceleration term (>= 32)")
            .param("threads", d.threads, "0: all cores (one hand per thread)")
            .param("w_hold", d.w_hold,
                   "where the object moves (the hinge turns) and no hand touches it (its top part), the nearer hand "
                   "is pulled onto it (ours; 0 = off, the paper's)")
            .param("w_limits", d.w_limits,
                   "anatomical finger-joint limits (ours; 0 = off, the paper's): core/hand/joint_limits.h")
            .param("w_pose", d.w_pose,
                   "finger pose held near the fit's: penetration resolved by moving the hand, not curling fingers "
                   "(ours; 0 = off, the paper's)")
            .param("w_separation", d.w_separation,
                   "fingers apart: two fingers' bones at least separation_gap apart (ours; 0 = off, the paper's)")
            .param("separation_gap", d.separation_gap, "m, the least distance between two fingers' bone axes")
            .param("constraint_growth", d.constraint_growth,
                   "a frame's separation and joint-limit terms grow with its penetration weight to this power (ours; 0: fixed)")
            .param("joint_angles", d.joint_angles,
                   "finger joints as angles bounded by their anatomical ranges (ours; false: axis-angles, the paper's)")
            .param("backtrack", d.backtrack,
                   "cut back a round's step in frames it took deeper into the object (ours; false: the paper's)")
            .param("w_pin", RefineDirections{}.w_pin,
                   "pinned wrists, orientations and poses (docs/directing.md): weight per pinned frame")
            .optional_input<HandConstraints>("hand_constraints",
                                             "pinned hands are held, hands kept off keep their clearance, the hold term "
                                             "leaves them (docs/directing.md)");
    refine_plugin::declare_hand_params(s);
    return s;
  }

  explicit CeresRefineStage(const Params& p) : hands_(refine_plugin::load_hand_pair(p)) {
    o_.w_proj = p.number("w_proj");
    o_.w_pen = p.number("w_pen");
    o_.w_acc = p.number("w_acc");
    o_.w_fit = p.number("w_fit");
    o_.outer_iterations = static_cast<int>(p.integer("rounds"));
    o_.max_iterations = static_cast<int>(p.integer("steps"));
    o_.max_outer_iterations = static_cast<int>(p.integer("max_rounds"));
    o_.pen_margin = p.number("pen_margin");
    o_.pen_exit_depth = p.number("pen_exit_depth");
    o_.pen_exit_smooth = static_cast<int>(p.integer("pen_exit_smooth"));
    o_.pen_cavities = p.boolean("pen_cavities");
    o_.pen_fingers_through = p.boolean("pen_fingers_through");
    o_.pen_tolerance = p.number("pen_tolerance");
    o_.pen_growth = p.number("pen_growth");
    o_.max_pen_boost = p.number("max_pen_boost");
    o_.accel_vertices = static_cast<int>(p.integer("accel_vertices"));
    o_.threads = static_cast<int>(p.integer("threads"));
    o_.w_hold = p.number("w_hold");
    o_.w_limits = p.number("w_limits");
    o_.w_pose = p.number("w_pose");
    o_.w_separation = p.number("w_separation");
    o_.separation_gap = p.number("separation_gap");
    o_.constraint_growth = p.number("constraint_growth");
    o_.joint_angles = p.boolean("joint_angles");
    o_.backtrack = p.boolean("backtrack");
    o_.validate();
    w_pin_ = p.number("w_pin");
    if (!(w_pin_ >= 0)) throw Error("'w_pin' must be >= 0");
  }

  void run(StageIO& io) override {
    const at::Tensor& states = io.in<at::Tensor>("object_states");
    const auto& object = io.in<ArticulatedObject>("object");
    const ObjectDistance distance(object);  // built once, shared by the samples
    const HeldFrames held = o_.w_hold > 0 ? held_frames(object, states) : HeldFrames{};
    const auto models = hands_->pointers();
    RefineDirections directions;
    if (io.has("hand_constraints")) directions = refine_directions(io.in<HandConstraints>("hand_constraints"), models, states);
    directions.w_pin = w_pin_;
    // A redrawn sample: its frames outside the stretch, and its shape, are kept as they were.
    std::optional<Sequence> kept;
    if (io.has("hand_constraints") && io.in<HandConstraints>("hand_constraints").keep) {
      const KeptSample& k = *io.in<HandConstraints>("hand_constraints").keep;
      kept = read_sequence(k.sample);
      if (kept->num_frames() != states.size(0))
        throw Error(fmt::format("refine.ceres: {} has {} frames, the run {}", k.sample, kept->num_frames(), states.size(0)));
      for (double w : k.weights(states.size(0))) directions.kept.push_back(w == 1.0);
    }
    refine_plugin::refine_samples(io, o_.threads, [&](std::size_t k, const at::Tensor& X, const HandMotion* given, int threads) {
      HandMotion start;
      if (given) {
        start = *given;
      } else {
        log::info("refine.ceres: no hand_params to start from; fitting MANO first (refine.mano_fit's defaults)");
        ManoFitOptions fit;
        fit.threads = threads;
        start = fit_mano(models, hand_features_to_world(X, states).positions, fit);
      }
      if (kept) start = with_kept_frames(start, kept->hands, directions.kept);
      RefineOptions o = o_;
      o.threads = threads;
      RefineReport report;
      HandMotion motion = refine_hands(models, distance, states, X, start, o, &report, held, directions);
      log::info("refine.ceres: {} frames in {:.2f} s (sample {})\n{}", X.size(0), report.seconds, k,
                format_refine_report(report));
      return motion;
    });
  }

 private:
  // `start` with the kept frames and the shape of `sample` (vertices dropped: they change).
  static HandMotion with_kept_frames(const HandMotion& start, const HandMotion& sample, const std::vector<bool>& kept) {
    HandMotion m;
    std::vector<std::int64_t> rows;
    for (std::size_t f = 0; f < kept.size(); ++f)
      if (kept[f]) rows.push_back(static_cast<std::int64_t>(f));
    const at::Tensor idx = at::tensor(rows, at::kLong);
    for (int h = 0; h < 2; ++h) {
      const HandParams &a = start.hands[static_cast<std::size_t>(h)], &b = sample.hands[static_cast<std::size_t>(h)];
      HandParams& o = m.hands[static_cast<std::size_t>(h)];
      o.rot = a.rot.clone().index_copy_(0, idx, b.rot.to(at::kFloat).index_select(0, idx));
      o.pose = a.pose.clone().index_copy_(0, idx, b.pose.to(at::kFloat).index_select(0, idx));
      o.trans = a.trans.clone().index_copy_(0, idx, b.trans.to(at::kFloat).index_select(0, idx));
      o.shape = b.shape.to(at::kFloat).clone();
    }
    return m;
  }

  std::shared_ptr<const refine_plugin::HandPair> hands_;
  RefineOptions o_;
  double w_pin_ = 0;
};

}  // namespace
}  // namespace bimart

BIMART_REGISTER_STAGE(bimart::CeresRefineStage)
