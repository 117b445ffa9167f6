#include "core/directing/refine_directions.h"

#include <ATen/ATen.h>
#include <fmt/format.h>

#include <map>

#include "core/geometry/rotation.h"
#include "core/hand/lbs.h"
#include "core/io/sequence.h"
#include "core/object/object_state.h"

namespace bimart {
namespace {

Eigen::Isometry3d pose_at(const at::Tensor& states, std::int64_t f) {
  const at::Tensor row = states[f].to(at::kDouble).contiguous();
  return canonical_to_world(ObjectState::from_row(row.data_ptr<double>()));
}

Eigen::VectorXd vec(const at::Tensor& t) {
  const at::Tensor d = t.to(at::kDouble).contiguous();
  return Eigen::Map<const Eigen::VectorXd>(d.data_ptr<double>(), d.numel());
}

// The hand of a pose pin at its source frame: wrist (world), orientation, fingers; and the
// object's pose there.
struct SourceHand {
  Eigen::Vector3d wrist;
  Eigen::Matrix3d rotation;
  Eigen::VectorXd fingers;
  Eigen::Isometry3d object;
};

SourceHand source_hand(const HandModel& model, const HandPin& pin) {
  const Sequence seq = read_sequence(pin.source);
  const HandParams& p = seq.hands.hands[static_cast<std::size_t>(pin.hand)];
  const std::int64_t f = pin.source_frame;
  const Eigen::VectorXd rot = vec(p.rot[f]), trans = vec(p.trans[f]), beta = vec(p.shape);
  const Eigen::Vector3d j0 = lbs<double>(model, Eigen::Vector3d::Zero(), Eigen::VectorXd::Zero(HandModel::kPoseDim),
                                         Eigen::Vector3d::Zero(), beta)
                                 .joints.row(0)
                                 .transpose();
  return {Eigen::Vector3d(trans) + j0, axis_angle_to_matrix(Eigen::Vector3d(rot)), vec(p.pose[f]),
          pose_at(seq.object_states, f)};
}

}  // namespace

RefineDirections refine_directions(const HandConstraints& constraints, const std::array<const HandModel*, 2>& hands,
                                   const at::Tensor& states) {
  const std::int64_t N = states.size(0);
  RefineDirections r;
  for (const ContactConstraint& c : constraints.contacts) {
    if (c.part != ContactPart::None) continue;
    auto& clear = r.clearance[static_cast<std::size_t>(c.hand)];
    if (clear.empty()) clear.assign(static_cast<std::size_t>(N), 0.0);
    for (std::int64_t f = c.frames.first; f <= std::min(c.frames.last, N - 1); ++f) clear[static_cast<std::size_t>(f)] = c.clearance;
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
        const Eigen::Isometry3d carry = pose_at(states, f) * src->object.inverse();
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

}  // namespace bimart
