// What the viewer page marks of a directed run (docs/directing.md): per hand, the frames a
// contact constraint or a pin covers, the pinned wrists (world frame, per frame) and the
// regions asked for; a redrawn stretch for both hands. The page draws them as a timeline
// under the frame slider and as markers in the scene (core/export/viewer/viewer.js).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/directing/hand_constraints.h"
#include "core/export/scene_source.h"

namespace bimart {

struct ViewerMark {
  int hand = 0;  // 0 left, 1 right, -1 both hands (a redrawn stretch)
  std::int64_t first = 0, last = 0;
  // top | bottom | any | none (contact constraints), wrist | pose (pins), redraw | contacts
  // (bimart edit: the stretch drawn anew; the sample's contact maps kept everywhere).
  std::string kind;
  std::string label;  // one line for the page, e.g. "right: wrist pinned (and turned), frame 75"
  // Pins: the pinned wrist (MANO's root joint, world frame, m) at each frame first..last.
  std::vector<std::array<double, 3>> wrists;
  // Regions: the point (object frame, hinge closed), its radius, and the part it lies on.
  std::optional<std::array<double, 3>> region_point;
  double region_radius = 0;
  std::string region_part;  // "top" | "bottom"
};

// The marks of `constraints` on the scene `source` (its object states carry pose pins to
// their frames). Constraints past the sequence's last frame are cut to it. Throws
// bimart::Error when a pose pin's sample cannot be read.
std::vector<ViewerMark> viewer_marks(const HandConstraints& constraints, const SceneSource& source);

}  // namespace bimart
