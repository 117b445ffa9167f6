// A procedural adult human hand in MANO's layout (core/hand/hand_model.h), shipped because
// the real MANO files cannot be (DESIGN §4). See docs/hand.md.
//
// Frame (MANO's right-hand rest frame): fingers point along -x, the palm faces -y, the thumb
// is on the +z side; a positive rotation about +z flexes the four fingers. The wrist joint
// sits at (0.095, 0.006, 0.006) m (our recollection of MANO's mean right wrist; nothing
// depends on it). The left hand is the mirror image x -> -x with the same vertex ids, so a right-hand
// axis-angle (a, b, c) corresponds to (a, -b, -c) on the left.
//
// Shape directions (beta = +1 is about +2 standard deviations of adult variation; the
// model is linear, so -1 is the opposite change):
//   0 size             whole hand +10 % about the wrist
//   1 palm width       palm and knuckle row +10 % across (thumb side to little-finger side)
//   2 palm length      wrist-to-knuckle +10 %
//   3 finger length    the four fingers' phalanges +10 %
//   4 finger thickness radius of all five digits +12 %
//   5 thumb length     the thumb's three bones +10 %
//   6 index/ring ratio index +3.5 %, ring -3.5 % (the 2D:4D ratio +7 %)
//   7 palm thickness   palm (back to front) +15 %
//   8 finger spread    index +4 deg, ring -4 deg, little finger -8 deg, thumb +4 deg in the palm plane
//   9 knuckle width    knuckle row +8 % wider relative to the wrist (a fan-shaped palm)
// Pose-corrective blend shapes are not modelled: posedirs is all zeros.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "core/hand/hand_model.h"

namespace bimart {

struct ProceduralHandOptions {
  int target_vertices = 800;
  int pose_samples = 4000;  // sampled finger poses for the PCA basis
  std::uint64_t seed = 7;   // pose samples
};

HandModel make_procedural_hand(HandSide side, const ProceduralHandOptions& options = {});

// The skeleton the hand is built around, for shape `betas` (10; empty = mean shape).
struct HandSkeleton {
  std::array<Eigen::Vector3d, 16> joints;  // MANO joint order
  std::array<Eigen::Vector3d, 5> tips;     // fingertip surface points: thumb, index, middle, ring, pinky
};
HandSkeleton procedural_hand_skeleton(HandSide side, const Eigen::VectorXd& betas = {});

// The names of the 10 shape directions, in order (see the list above).
const std::array<std::string, 10>& procedural_shape_names();

// A finger pose (45 axis-angle values, flat convention, right or left per `side`): the four
// fingers curled by `curl` (0 flat, 1 a loose fist) and the thumb by `thumb_curl`. The same
// synergy the PCA basis is sampled from.
Eigen::VectorXd procedural_curl_pose(HandSide side, double curl, double thumb_curl);

// The same synergy per digit, in MANO digit order (index, middle, pinky, ring, thumb): each
// digit's curl (0 straight, 1 a loose fist) and its spread in the palm plane (rad, about
// the palm normal at the first joint). Linear in both, so blending two such poses blends
// their curls.
Eigen::VectorXd procedural_digit_pose(HandSide side, const std::array<double, 5>& curl,
                                      const std::array<double, 5>& spread);

}  // namespace bimart
