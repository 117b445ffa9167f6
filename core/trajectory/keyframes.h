// Keyframes to frames (docs/trajectories.md, "Keyframes"). Each channel — position, root
// rotation, hinge angle — is interpolated over the keys that give it: positions and angle by
// cubic splines (C², core/trajectory/cubic_spline.h), rotations by a cubic spline in the
// tangent space of the first rotation key (core/trajectory/rotation_spline.h). With `rest`
// every channel starts and ends at zero velocity (clamped ends) and holds its first and last
// key value outside its keys; without it the ends are natural and channels continue at their
// end velocity. A channel no key gives stays at zero (identity rotation, closed hinge).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/trajectory/trajectory.h"

namespace bimart {

struct Keyframe {
  double t = 0;  // seconds
  int line = 0;  // in the keyframe file, for messages
  std::optional<Eigen::Vector3d> position;     // root translation (m)
  std::optional<Eigen::Quaterniond> rotation;  // root rotation
  std::optional<double> angle;                 // hinge angle (rad)
};

// Frames at t0 + k / fps, k = 0 .. N - 1, from the first key t0 up to the last key.
std::int64_t keyframe_count(double first_time, double last_time, double fps);

// Fills trajectory.states, lines, angle_keys, start_time and fps. Throws bimart::Error at
// `file` and the key's line when times do not strictly increase, a value is not finite, or
// the frame count is outside [2, kMaxTrajectoryFrames].
void sample_keyframes(const std::vector<Keyframe>& keys, double fps, bool rest, const std::string& file,
                      Trajectory& trajectory);

}  // namespace bimart
