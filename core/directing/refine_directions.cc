#include "core/directing/refine_directions.h"

#include <algorithm>

#include <ATen/ATen.h>
#include <fmt/format.h>


#include "core/geometry/rotation.h"
#include "core/hand/lbs.h"

namespace bimart {
namespace {

// The hand of a pose pin at its source frame: wrist (world), orientation, fingers; and the
// object's pose there.
struct SourceHand {
  Eigen::Vector3d wrist;
  Eigen::Matrix3d rotation;
  Eigen::VectorXd fingers;
  Eigen::Isometry3d object;
};

SourceHand source_hand(const HandModel& model, const HandPin& pin) {
  const PinnedPose src = read_pinned_pose(pin);
  const Eigen::Vector3d j0 = lbs<double>(model, Eigen::Vector3d::Zero(), Eigen::VectorXd::Zero(HandModel::kPoseDim),
                                         Eigen::Vector3d::Zero(), src.shape)
                                 .joints.row(0)
                                 .transpose();
  return {src.trans + j0, axis_angle_to_matrix(src.rot), src.pose, src.object};
}

}  // namespace

RefineDirections refine_directions(const HandConstraints& constraints, const std::array<const HandModel*, 2>& hands,
                                   const at::Tensor& states) {
  const std::int64_t N = states.size(0);
  RefineDirections r;
  for (const ContactConstraint& c : constraints.contacts) {
    if (c.part != ContactPart::None) {  // the hold term keeps the hand on its part
      auto& hold = r.hold[static_cast<std::size_t>(c.hand)];
      if (hold.empty()) hold.assign(static_cast<std::size_t>(N), -1);
      const ObjectPart part = c.part == ContactPart::Top      ? ObjectPart::Top
                              : c.part == ContactPart::Bottom ? ObjectPart::Bottom
                                                              : ObjectPart::Whole;
      for (std::int64_t f = std::max<std::int64_t>(c.frames.first, 0); f <= std::min(c.frames.last, N - 1); ++f)
        hold[static_cast<std::size_t>(f)] = static_cast<int>(part);
      continue;
    }
    auto& clear = r.clearance[static_cast<std::size_t>(c.hand)];
    if (clear.empty()) clear.assign(static_cast<std::size_t>(N), 0.0);
    const FrameRange span = c.with_ramps(N);
    for (std::int64_t f = span.first; f <= span.last; ++f)
      clear[static_cast<std::size_t>(f)] = std::max(clear[static_cast<std::size_t>(f)], c.clearance_at(f));
  }
  if (!constraints.contacts.empty()) std::tie(r.may_hold, r.may_hold_top) = hands_that_may_hold(constraints, N);
  for (const HandPin& pin : constraints.pins) {
    if (pin.frames.last >= N)
      throw Error(pin.where, fmt::format("frames up to {}, but the trajectory has {} frames", pin.frames.last, N));
    std::optional<SourceHand> src;
    if (pin.whole_pose()) src = source_hand(*hands[static_cast<std::size_t>(pin.hand)], pin);
    for (std::int64_t f = pin.frames.first; f <= pin.frames.last; ++f) {
      RefineDirections::Pin p;
      p.frame = f;
      if (src) {
        const Eigen::Isometry3d carry = object_pose_at(states, f) * src->object.inverse();
        p.wrist = carry * src->wrist;
        p.rotation = Eigen::Matrix3d(carry.linear() * src->rotation);
        p.fingers = src->fingers;
      } else {
        p.wrist = *pin.wrist;
        if (pin.rotation) p.rotation = pin.rotation->toRotationMatrix();
      }
      r.pins[static_cast<std::size_t>(pin.hand)].push_back(p);
    }
  }
  return r;
}

RefineDirections pinned_targets(std::vector<HandPin>& pins, const std::array<const HandModel*, 2>& hands,
                                const at::Tensor& states) {
  HandConstraints only;
  for (HandPin& p : pins) p.frames.last = std::min(p.frames.last, states.size(0) - 1);
  only.pins = pins;
  return refine_directions(only, hands, states);
}

}  // namespace bimart
