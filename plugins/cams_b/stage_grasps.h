// CAMS-B's hands (docs/baselines.md): for each manipulation stage and hand, a grasp placed
// at the stage's contact target — on the part holding most of the target's contact points,
// at a site near their centre, by the synthetic engine's grasp planner (core/synth/grasp.h:
// palm against the surface, fingers closed until they touch) — held on its part through the
// stage and blended into the next stage's over a few frames. A hand whose target has no
// contact point waits away from the object. CAMS plans its hands so from its stage-wise
// targets; the refinement (refine.ceres) then fits them against the object over time.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/hand/hand_model.h"
#include "core/hand/hand_motion.h"
#include "core/object/articulated_object.h"
#include "core/object/object_distance.h"
#include "manipulation_stages.h"

namespace bimart {

struct StageGraspOptions {
  double contact = 0.01;      // m: a target point is a contact point when its map value is below this
  double site_radius = 0.03;  // m: the grasp's site within this of the contact points' centre (doubled, then any site, on failure)
  std::int64_t blend = 8;     // frames over which one stage's grasp turns into the next's
  double max_depth = 0.004;   // m: the planner's deepest vertex
};

// One sample's hands: targets C [N, 2, M] (stage-wise, m), the basis rows' object vertices
// hits [N, M] (indices into [top; bottom]), the object and its states [N, 7].
HandMotion stage_grasp_hands(const ArticulatedObject& object, const ObjectDistance& distance,
                             const std::array<const HandModel*, 2>& models, const at::Tensor& states,
                             const at::Tensor& targets, const at::Tensor& hits,
                             const std::vector<ManipulationStage>& stages, const StageGraspOptions& options,
                             std::uint64_t seed);

}  // namespace bimart
