// How well a sample keeps the hand constraints it was made with (docs/directing.md): per
// constraint one measurement on the posed hands and the object, and whether it holds.
//   part top/bottom/any   frames of the range where the hand touches that part (a vertex
//                         within 5 mm, DESIGN §6), and within the region when one is given;
//                         holds when at least 90 % of the range does
//   part none             the hand's smallest distance to the object over the range; holds
//                         when it is the clearance (1 mm tolerance)
//   wrist / pose pin      the wrist's distance to its pin (and the orientation's angle, the
//                         fingers' pose); holds within 5 mm (and 5 degrees)
//   a redrawn stretch     frames outside it bit-identical to the kept sample
// `bimart constraints SAMPLES --hands FILE` prints it.
#pragma once

#include <string>
#include <vector>

#include "core/directing/hand_constraints.h"
#include "core/export/scene_source.h"

namespace bimart {

struct ConstraintCheck {
  std::string asked;     // e.g. "right: on the top part, frames 12-60"
  std::string measured;  // e.g. "touches it in 47 of 49 frames (95.9 %)"
  double value = 0;      // the measurement: share of frames, or metres
  bool holds = false;
};

// Throws bimart::Error when a pose pin's or the kept sample's file cannot be read.
std::vector<ConstraintCheck> check_constraints(const HandConstraints& constraints, const SceneSource& source);

}  // namespace bimart
