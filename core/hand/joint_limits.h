// Anatomical finger-joint limits (issue 38), as penalties the MANO fit and the refinement
// add to their costs. Each of the 15 finger joints' axis-angle rotation (MANO's pose, in
// the rest frame, relative to the parent joint) is read as three angles about axes taken
// from the model's rest skeleton, so the same limits hold for the procedural hand and for
// MANO's real files, either side:
//   d  the bone the joint moves (the joint to its child joint; the last joint's bone
//      continues the one before it, as the rest hand is flat);
//   a  the flexion axis, d × palm normal: a bend about +a turns the bone towards the palm;
//   flexion   the bent bone d' = R d's turn about a, atan2(d'·(a × d), d'·d);
//   abduction its angle out of the flexion plane, atan2(d'·a, |d' − (d'·a) a|);
//   twist     the rotation's twist about d (swing-twist split of its quaternion).
// The thumb bends about axes that vary between hands and models more than the fingers', so
// its joints limit the swing (the angle from d to d', unsigned) and the twist.
// The ranges (degrees) are the fingers' ranges of motion usually quoted in the hand
// literature (MCP flexion 0–90 with up to 20–30 of hyperextension, PIP 0–110, DIP 0–80 with
// a little hyperextension, MCP abduction about ±20, almost none at PIP and DIP), each with a
// few degrees more, so that the synthetic data's grasps (which reach curl 1.1) stay inside.
// The plausibility measure (core/metrics/hand_plausibility.h) flags joints a further margin
// outside these ranges, measured on joints regressed from the vertices.
#pragma once

#include <array>
#include <cmath>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/jet.h>
#include <ceres/rotation.h>

#include "core/hand/hand_model.h"

namespace bimart {

struct AngleRange {
  double lo, hi;  // degrees
};
struct JointLimit {
  AngleRange flex, abduct, twist;  // fingers; the thumb uses flex.hi as its largest swing
};
struct AnatomicalLimits {
  JointLimit mcp{{-30, 100}, {-25, 25}, {-20, 20}};
  JointLimit pip{{-10, 115}, {-12, 12}, {-20, 20}};
  JointLimit dip{{-15, 95}, {-12, 12}, {-20, 20}};
  JointLimit thumb_cmc{{0, 90}, {0, 0}, {-45, 45}};
  JointLimit thumb_mcp{{0, 80}, {0, 0}, {-30, 30}};
  JointLimit thumb_ip{{0, 95}, {0, 0}, {-30, 30}};
};
inline constexpr AnatomicalLimits kAnatomicalLimits{};

class JointLimits {
 public:
  // Axes from the model's rest skeleton (β = 0). Throws bimart::Error for a model whose
  // bones have no length.
  explicit JointLimits(const HandModel& model, const AnatomicalLimits& limits = kAnatomicalLimits);

  // Joint j (0..14: MANO joints 1..15) at axis-angle aa: three residuals, each the angle
  // (radians) by which flexion (thumb: swing), abduction and twist leave their ranges,
  // 0 inside. Templated for Ceres' Jets.
  template <class T>
  void excess(int j, const T* aa, T* r) const;
  // excess() of joints first .. first + count − 1 (their axis-angles consecutive in aa),
  // each residual times `scale`: 3·count residuals, for the fit's and the refinement's costs.
  template <class T>
  void scaled_excess(int first, int count, const T* aa, double scale, T* r) const {
    for (int k = 0; k < count; ++k) {
      excess(first + k, aa + 3 * k, r + 3 * k);
      for (int c = 0; c < 3; ++c) r[3 * k + c] *= scale;
    }
  }
  // Σ of the squared excesses (rad²) of a finger pose [45].
  double squared_excess(const double* pose) const {
    double r[45], sum = 0;
    scaled_excess(0, 15, pose, 1.0, r);
    for (const double v : r) sum += v * v;
    return sum;
  }
  // Joint j's rotation as three angles (radians), the refinement's bounded parameters: the
  // bone turned by flexion about a towards the palm and by abduction towards a,
  //   d' = cos(abd) (cos(flex) d + sin(flex) a×d) + sin(abd) a,
  // the rotation the shortest swing from d onto d' after a twist about d. For the fingers
  // flexion, abduction and twist are exactly those angles() reads; for the thumb flexion and
  // abduction are the two components of its swing. parameters() is rotation()'s inverse
  // for any rotation whose swing is under π.
  template <class T>
  void rotation(int j, const T* angle, T* aa) const;
  Eigen::Vector3d parameters(int j, const Eigen::Vector3d& aa) const;
  // The box rotation()'s angles are kept in (radians): the ranges for the fingers; for the
  // thumb ±its largest swing M on flexion and abduction (abduction at most ±90°; cos swing = cos flex · cos abd, so
  // for M ≥ 90° the box lies inside the range; below, its corners reach acos(cos² M):
  // 80° → 88°, which excess() and clamp() see to) and its twist range.
  std::array<AngleRange, 3> bounds(int j) const;
  // Flexion (thumb: swing), abduction and twist of joint j at aa, degrees.
  Eigen::Vector3d angles(int j, const Eigen::Vector3d& aa) const;
  // Joint j's rotation moved into its ranges: flexion (thumb: swing), abduction and twist
  // each clamped, the rotation rebuilt from them (swing onto the clamped bone direction,
  // then the twist about the rest bone). Unchanged when inside. Returns whether it moved.
  bool clamp(int j, Eigen::Vector3d* aa) const;
  // clamp() of every joint of a finger pose [45] (45 values from `pose`); the count moved.
  int clamp_pose(double* pose) const;
  // The largest excess over a finger pose [45], degrees; `where` (optional) names the joint
  // and angle ("index PIP flexion 131°").
  double largest_excess(const Eigen::VectorXd& pose, std::string* where = nullptr) const;

 private:
  struct Frame {
    Eigen::Vector3d d, a, ad;  // bone, flexion axis, a × d (towards the palm)
    JointLimit limit;          // radians
    bool thumb = false;
  };
  std::array<Frame, 15> frames_;

  // Flexion (thumb: swing), abduction (thumb: 0) and twist of joint j at aa, radians.
  template <class T>
  void raw_angles(int j, const T* aa, T* angle) const;
  template <class T>
  static T outside(const T& angle, double lo, double hi) {
    if (angle > T(hi)) return angle - T(hi);
    if (angle < T(lo)) return T(lo) - angle;
    return T(0);
  }
};

template <class T>
void JointLimits::raw_angles(int j, const T* aa, T* angle) const {
  using std::atan2;
  using std::cos;
  using std::sin;
  using std::sqrt;
  const Frame& f = frames_[static_cast<std::size_t>(j)];
  const T d[3] = {T(f.d[0]), T(f.d[1]), T(f.d[2])};
  T b[3];  // the bent bone
  ceres::AngleAxisRotatePoint(aa, d, b);
  const T along = b[0] * f.d[0] + b[1] * f.d[1] + b[2] * f.d[2];
  const T side = b[0] * f.a[0] + b[1] * f.a[1] + b[2] * f.a[2];
  const T palm = b[0] * f.ad[0] + b[1] * f.ad[1] + b[2] * f.ad[2];
  if (f.thumb) {
    angle[0] = atan2(sqrt(side * side + palm * palm + T(1e-18)), along);
    angle[1] = T(0);
  } else {
    angle[0] = atan2(palm, along);
    angle[1] = atan2(side, sqrt(along * along + palm * palm + T(1e-18)));
  }
  // Twist: 2 atan2(sin(θ/2)/θ · (ω·d), cos(θ/2)), with its series near θ = 0.
  const T theta2 = aa[0] * aa[0] + aa[1] * aa[1] + aa[2] * aa[2];
  const T w_d = aa[0] * f.d[0] + aa[1] * f.d[1] + aa[2] * f.d[2];
  T s, c;
  if (theta2 < T(1e-10)) {
    s = T(0.5) - theta2 / T(48);
    c = T(1) - theta2 / T(8);
  } else {
    const T theta = sqrt(theta2);
    s = sin(theta / T(2)) / theta;
    c = cos(theta / T(2));
  }
  // q and −q are one rotation: the twist of the one with cos(θ/2) ≥ 0, in [−π, π] (an
  // axis-angle wound past π, as a solver may leave it, is the short turn the other way).
  if (c < T(0)) {
    s = -s;
    c = -c;
  }
  angle[2] = T(2) * atan2(s * w_d, c);
}

template <class T>
void JointLimits::rotation(int j, const T* angle, T* aa) const {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const Frame& f = frames_[static_cast<std::size_t>(j)];
  const T cf = cos(angle[0]), sf = sin(angle[0]), ca = cos(angle[1]), sa = sin(angle[1]);
  T b[3];  // d'
  for (int i = 0; i < 3; ++i) b[i] = ca * (cf * f.d[i] + sf * f.ad[i]) + sa * f.a[i];
  // The swing's quaternion (1 + d·d', d × d') normalised: w = cos(φ/2), v = d×d' / (2w).
  const T c = b[0] * f.d[0] + b[1] * f.d[1] + b[2] * f.d[2];
  const T w = sqrt((T(1) + c) / T(2));
  const T v[3] = {(f.d[1] * b[2] - f.d[2] * b[1]) / (T(2) * w), (f.d[2] * b[0] - f.d[0] * b[2]) / (T(2) * w),
                  (f.d[0] * b[1] - f.d[1] * b[0]) / (T(2) * w)};
  // Times the twist (cos(τ/2), sin(τ/2) d); v ⊥ d, so the product's w is w·cos(τ/2).
  const T ct = cos(angle[2] / T(2)), st = sin(angle[2] / T(2));
  T q[4];
  q[0] = w * ct;
  for (int i = 0; i < 3; ++i) q[1 + i] = v[i] * ct + w * st * f.d[i];
  q[1] += (v[1] * f.d[2] - v[2] * f.d[1]) * st;
  q[2] += (v[2] * f.d[0] - v[0] * f.d[2]) * st;
  q[3] += (v[0] * f.d[1] - v[1] * f.d[0]) * st;
  ceres::QuaternionToAngleAxis(q, aa);
}

template <class T>
void JointLimits::excess(int j, const T* aa, T* r) const {
  T angle[3];
  raw_angles(j, aa, angle);
  const JointLimit& L = frames_[static_cast<std::size_t>(j)].limit;
  r[0] = outside(angle[0], L.flex.lo, L.flex.hi);
  r[1] = frames_[static_cast<std::size_t>(j)].thumb ? T(0) : outside(angle[1], L.abduct.lo, L.abduct.hi);
  r[2] = outside(angle[2], L.twist.lo, L.twist.hi);
}

}  // namespace bimart
