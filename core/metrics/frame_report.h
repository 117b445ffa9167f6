// One row per frame and hand of a sequence, for finding the frames behind a table's
// percentages (`bimart eval --frames FILE.csv`, docs/metrics.md): how deep the hand is in
// the object, which part of the hand is deepest and whether it passed through a part, how
// deep it is in a cavity, and why it is implausible.
#pragma once

#include <array>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/hand/hand_model.h"
#include "core/object/object_distance.h"

namespace bimart {

struct HandFrameRow {
  std::int64_t frame = 0;
  int hand = 0;              // 0 left, 1 right
  double depth = 0;          // m: the deepest vertex's signed distance to the object (> 0 inside, < 0 clearance)
  int vertex = -1;           // the deepest vertex when inside, else -1
  std::string region;        // its joint by skinning weight ("index3", "wrist"), when inside
  std::string part;          // the object part it is in ("top", "bottom"), when inside
  bool through = false;      // its nearest surface faces away from the hand's centre: it passed through a part
  double cavity = 0;         // m: deepest vertex in a part's cavity (ObjectDistance::max_cavity_depth, floor 5 mm)
  double closest_fingers = 0;  // m: the closest two fingers' bone axes come (kCrossedGap flags)
  std::string implausible;   // why the hand is implausible (core/metrics/hand_plausibility.h), else empty
};

// `states` [N, 7], `vertices` [2, N, V, 3] world frame posed with `models` {left, right}.
std::vector<HandFrameRow> hand_frame_rows(const ObjectDistance& distance, const at::Tensor& states,
                                          const at::Tensor& vertices, const std::array<const HandModel*, 2>& models);

// CSV: a header (with_header) and one line per row, the sequence's name first; lengths in mm.
void write_frame_rows_csv(std::ostream& out, const std::string& sequence, const std::vector<HandFrameRow>& rows,
                          bool with_header);

}  // namespace bimart
