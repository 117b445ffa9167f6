// Synthetic 7-DoF object trajectories (DESIGN §7): the object rests on a table, both hands
// approach, then a *grab* (lift, carry, turn, put down; hinge fixed) or a *use* (open and/or
// close the hinge, sometimes while sliding or held in the air), then the hands release and
// retreat. Segments are minimum-jerk; the ranges come from core/synth/motion_table.h.
//
// World frame: y up, table top at y = 0, the person on the +z side facing -z (their right
// is +x).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/object/articulated_object.h"
#include "core/object/object_state.h"

namespace bimart {

enum class SequenceKind { Grab, Use };
const char* kind_name(SequenceKind kind);  // "grab", "use"

struct TrajectoryOptions {
  double fps = 30;
  int min_frames = 120;
  int max_frames = 300;
};

struct Trajectory {
  SequenceKind kind = SequenceKind::Grab;
  double fps = 30;
  std::vector<ObjectState> states;  // one per frame
  // The object is still before `first_move` and after `last_move` + 1: it moves from t to
  // t + 1 only for first_move <= t <= last_move. Hands hold it on that whole span.
  int first_move = 0;
  int last_move = 0;

  int num_frames() const { return static_cast<int>(states.size()); }
  at::Tensor tensor() const;  // [N, 7] float32
};

// A random trajectory of `kind` for `object` (its category selects the table row); the
// same seed gives the same trajectory.
Trajectory plan_trajectory(const ArticulatedObject& object, SequenceKind kind, std::uint64_t seed,
                           const TrajectoryOptions& options = {});

// Rotation taking the canonical frame to its resting orientation (category's `up` to +y,
// its `front` towards +z), turned by `yaw` about the vertical.
Eigen::Matrix3d resting_rotation(const ArticulatedObject& object, double yaw);
// The height (root translation y) at which the object with root rotation `rotation` and
// hinge `angle` rests on the table.
double resting_height(const ArticulatedObject& object, const Eigen::Matrix3d& rotation, double angle);

// 10u³ − 15u⁴ + 6u⁵ for u in [0, 1] (clamped): the minimum-jerk profile.
double min_jerk(double u);

}  // namespace bimart
