// Bimanual hand motion for a synthetic trajectory (DESIGN §7): roles and contact regions,
// grasps (core/synth/grasp.h), approach from an open pre-grasp pose 10–25 cm away, holding
// (a hand on the top part follows the hinge, a hand on the bottom follows the root), release
// and retreat. Every candidate motion is checked frame by frame — hand–object depth,
// hand–hand clearance, the table — and re-planned when it fails.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "core/hand/hand_model.h"
#include "core/hand/hand_motion.h"
#include "core/object/articulated_object.h"
#include "core/object/object_distance.h"
#include "core/synth/trajectory.h"

namespace bimart {

struct InteractionOptions {
  double max_depth = 0.002;       // no hand vertex deeper inside the object while holding (m)
  double max_depth_moving = 0.0049;  // ... nor during approach and release (below Pen 5mm)
  double hand_clearance = 0.002;  // minimum distance between the two hands' vertices (m)
  double table_clearance = -0.002;  // lowest hand vertex height allowed (m; the table is y = 0)
  int attempts = 6;               // full re-plans before giving up
};

struct InteractionInfo {
  ObjectPart part[2] = {ObjectPart::Bottom, ObjectPart::Bottom};  // what each hand holds
  int driver = -1;     // use sequences: the hand on the top part (0 left, 1 right)
  int attempts = 0;    // plans made until one passed
  double depth = 0;    // deepest hand vertex over all frames (m)
  double clearance = 0;  // closest approach of the two hands (m)
  int grasp_frame[2] = {0, 0};
  int release_frame[2] = {0, 0};
};

// Hands for `trajectory` on `object` (`distance` built from it), with `models` = {left,
// right}. Deterministic in `seed`. Throws bimart::Error when no valid motion was found.
HandMotion synthesize_hands(const ArticulatedObject& object, const ObjectDistance& distance,
                            const std::array<const HandModel*, 2>& models, const Trajectory& trajectory,
                            std::uint64_t seed, const InteractionOptions& options = {},
                            InteractionInfo* info = nullptr);

// World pose of a part at a state: the top part's frame is its rest frame (angle 0).
Eigen::Isometry3d world_from_part(const ObjectState& state, ObjectPart part);

}  // namespace bimart
