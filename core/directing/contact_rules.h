// Contact constraints (core/directing/hand_constraints.h) as rules on contact maps C
// [.., 2, 1024] (metres, one entry per object point the BPS basis hits), imposed on the
// contact model's prediction at every denoising step and on its result:
//   part: none     every entry of that hand at least `clearance`: the hand stays off;
//   part: top/bottom/any (+ region)
//                  entries on the other part (and, with a region, farther than
//                  radius + kRegionReach from its point) at least kOtherPartGap; and when
//                  none of the allowed entries (the part, inside the region) is at 0, the
//                  allowed entries are shifted down by their minimum, so the hand touches
//                  there — where the sampled map already came nearest.
// The guidance, the motion model and the refinement then follow C as they always do.
#pragma once

#include <cstdint>
#include <vector>

#include <ATen/core/Tensor.h>

#include "core/directing/hand_constraints.h"
#include "core/object/articulated_object.h"
#include "stages/sample_constraint.h"

namespace bimart {

// m: entries of a part a hand must not touch are kept this far: beyond the 5 mm contact
// test (DESIGN §6) with room for the map's sparse points.
constexpr double kOtherPartGap = 0.01;
// m: with a region, a hand touching inside it still covers this much around it (a palm).
constexpr double kRegionReach = 0.08;

class ContactRules : public SampleConstraint {
 public:
  // hit_indices [N, 1024] int64 into [top; bottom] vertices (an encoder's
  // basis_hit_indices). Throws, naming the constraint's line, for frames beyond N and for a
  // region with no object point of its part inside it.
  ContactRules(const HandConstraints& constraints, const ArticulatedObject& object, const at::Tensor& hit_indices);

  bool empty() const { return empty_; }
  // C [B, T, 2, 1024] or [B, T, 2048] (metres) for frames [first, first + T): the maps with the rules imposed.
  at::Tensor impose(const at::Tensor& maps, std::int64_t first_frame, int step, int num_steps) const override;

 private:
  bool empty_ = true;
  at::Tensor floor_;     // [N, 2, 1024] float: entries at least this
  at::Tensor required_;  // [N, 2, 1024] bool: the hand touches among these (none set: no requirement)
  at::Tensor touch_;     // [N, 2] bool
};

}  // namespace bimart
