// Pinned hands and hands kept off the object (core/directing/hand_constraints.h) imposed on
// the motion model's prediction X = [H | D] (canonical object frame) at every denoising
// step — in-painting in the keypoint space:
//   wrist pin     the hand's keypoints moved rigidly so its wrist is at the pin (and turned
//                 to the pinned orientation when one is given). The wrist and the hand's
//                 orientation are read from its palm keypoints by a rigid fit (Kabsch) to
//                 the hand model's flat rest palm, whose wrist joint is known;
//   pose pin      the hand's keypoints replaced by those of the sample's hand at its frame,
//                 relative to the object as they were there;
//   part: none    a hand whose keypoints come within `clearance` of the object points is
//                 moved rigidly away from the object until they do not (the clearance
//                 fading in and out over the constraint's ramp frames around its range).
// A pinned frame's change of every keypoint also moves the frames around it, weighted by
// a Gaussian of `sigma` frames (the pinned frames exactly), so the motion runs smoothly into
// the pin. D moves opposite to H, so H + D (the object point each keypoint refers to) stays.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include <ATen/core/Tensor.h>
#include <Eigen/Core>

#include "core/directing/hand_constraints.h"
#include "core/geometry/nearest_points.h"
#include "core/hand/hand_model.h"
#include "stages/sample_constraint.h"

namespace bimart {

class HandPins : public SampleConstraint {
 public:
  // states [N, 7] (object states of the run), object_points [N, 1024, 3] (canonical frame,
  // articulated: basis_hit_points) for the hands kept off. sigma: frames.
  HandPins(const HandConstraints& constraints, const std::array<const HandModel*, 2>& hands, const at::Tensor& states,
           const at::Tensor& object_points, double sigma = 4.0);

  bool empty() const { return targets_.empty() && away_.empty(); }
  at::Tensor impose(const at::Tensor& x0, std::int64_t first_frame, int step, int num_steps) const override;

  // The wrist (world frame) that the keypoints H [J, 3] of `hand` (canonical frame, frame
  // `frame` of the run) imply, and the hand's orientation (world): for tests and checks.
  std::pair<Eigen::Vector3d, Eigen::Matrix3d> wrist_of(const at::Tensor& keypoints, int hand, std::int64_t frame) const;

  using Keys = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;
  struct Target {
    int hand = 0;
    std::int64_t frame = 0;
    Eigen::Vector3d wrist;     // canonical frame
    bool turn = false;         // rotation pinned
    Eigen::Matrix3d rotation;  // canonical frame
    Keys keypoints;            // [J, 3] canonical (pose pin), else empty
  };

 private:
  struct Palm {
    Points3 rest;            // [P, 3]: the palm keypoints of the flat rest hand
    Eigen::Vector3d wrist;   // its wrist joint
    std::vector<int> index;  // [P]: which of the J keypoints are on the palm
  };
  // Rotation R and wrist w of a hand from its keypoints [J, 3] (canonical frame).
  std::pair<Eigen::Matrix3d, Eigen::Vector3d> fit_palm(const Eigen::Ref<const Keys>& keypoints, int hand) const;

  std::array<Palm, 2> palms_;
  std::vector<Target> targets_;
  std::vector<ContactConstraint> away_;  // part: none
  // Per frame a hand is kept off at (ramps included): the object points' k-d tree and centre.
  std::map<std::int64_t, NearestPoints> trees_;
  std::map<std::int64_t, Eigen::Vector3d> centres_;
  at::Tensor states_;  // [N, 7] float64
  at::Tensor points_;  // [N, 1024, 3] float32
  double sigma_;
};

}  // namespace bimart
