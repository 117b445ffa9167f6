// Checks on a trajectory that readers cannot make alone: the frame-count bounds, finite
// numbers, and the hinge angle against the object's limits (docs/trajectories.md,
// "Validation"). Every message names the file and the line (or frame) at fault.
#pragma once

#include <cstdint>
#include <string>

#include "core/object/articulated_object.h"
#include "core/trajectory/trajectory.h"

namespace bimart {

// Hinge angles may exceed the limits by this much (rad) before they count as outside:
// rounding of degrees written in a file.
constexpr double kHingeLimitTolerance = 1e-6;

// Throws bimart::Error at `where` when n is outside [2, kMaxTrajectoryFrames]; `what`
// describes where the count came from ("120 rows", "keys from ... at 30 fps").
void check_frame_count(std::int64_t n, const SourceLocation& where, const std::string& what);

// Every number finite, the frame count within bounds, fps positive, and every hinge angle
// (of each key, then of each frame) within [angle_min, angle_max] of `object`.
void validate_trajectory(const Trajectory& trajectory, const ArticulatedObject& object);

}  // namespace bimart
