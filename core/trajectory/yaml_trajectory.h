// Trajectories in YAML (docs/trajectories.md): either per-frame
//
//   fps: 30
//   object: {category: laptop, seed: 3}   # or a path: ../objects/my_box
//   frames:                               # 7 numbers per frame: rad and m (DESIGN §4)
//     - [0.0, 0, 0, 0, 0, 0, 0]
//
// or keyframes, sampled at the stage's fps (else the file's, else 30):
//
//   rest: true                # zero velocity at the first and last key (default)
//   keys:
//     - t: 0                  # seconds
//       position: [0, 0, 0]   # root translation, m
//       rotation: {euler_xyz: [0, 0, 0]}   # degrees; or {axis_angle: [x, y, z]} (length = degrees)
//       angle: 0              # hinge, degrees
//
// Unknown keys, duplicate keys, wrong types and non-finite numbers are errors naming the
// file and line.
#pragma once

#include <string>

#include "core/trajectory/trajectory.h"

namespace bimart {

// `fps` > 0 samples keyframes at it; 0 uses the file's `fps:`, else kDefaultTrajectoryFps.
// For per-frame files fps is the file's (0 when it gives none).
Trajectory read_yaml_trajectory(const std::string& path, double fps = 0);

}  // namespace bimart
