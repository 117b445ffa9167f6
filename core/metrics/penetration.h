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

}  // namespace bimart
