// Pen (DESIGN §6): frames whose deepest hand vertex is more than `threshold` inside the
// object (strictly: a vertex exactly at the threshold does not count). The paper reports
// 1 cm and 5 mm.
#pragma once

#include "core/metrics/frame_count.h"
#include "core/metrics/frame_depths.h"

namespace bimart {

constexpr double kPenetration1cm = 0.01;   // m
constexpr double kPenetration5mm = 0.005;  // m
constexpr double kPenetration3mm = 0.003;  // m

// hits = frames with whole-object depth > threshold; frames = all frames.
FrameCount penetration_frames(const FrameDepths& depths, double threshold);

// Cavity (ours, issue 38): frames with a hand vertex more than kCavityDepth inside a part's
// convex hull while outside the object — a hand inside a hollow part, which Pen cannot see.
// On solid, nearly convex parts it is 0; concave ones (handles, the gap of a drip tray) can
// hold a hand legitimately, so read it beside the ground truth's.
constexpr double kCavityDepth = 0.01;  // m
FrameCount cavity_frames(const FrameDepths& depths);

}  // namespace bimart
