#include "core/hand/joint_limits.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/util/error.h"

namespace bimart {
namespace {

constexpr double kRad = M_PI / 180.0;
// MANO joint order: wrist; index 1-3, middle 1-3, pinky 1-3, ring 1-3, thumb 1-3.
constexpr std::array<const char*, 5> kDigit{"index", "middle", "pinky", "ring", "thumb"};
constexpr std::array<const char*, 3> kFingerJoint{"MCP", "PIP", "DIP"};
constexpr std::array<const char*, 3> kThumbJoint{"CMC", "MCP", "IP"};

JointLimit in_radians(const JointLimit& l) {
  const auto r = [](const AngleRange& a) { return AngleRange{a.lo * kRad, a.hi * kRad}; };
  return {r(l.flex), r(l.abduct), r(l.twist)};
}

}  // namespace

JointLimits::JointLimits(const HandModel& m, const AnatomicalLimits& limits) {
  const Eigen::Matrix<double, 16, 3> J = m.j_regressor * m.v_template;
  const auto joint = [&](int i) -> Eigen::Vector3d { return J.row(i).transpose(); };
  const double side = m.side == HandSide::Left ? -1.0 : 1.0;
  const Eigen::Vector3d lateral = joint(1) - joint(7), along = joint(4) - joint(0);
  const Eigen::Vector3d palm = side * lateral.cross(along);
  if (palm.norm() < 1e-9) throw Error("joint limits: the hand model's rest knuckles and wrist are collinear");
  for (int j = 0; j < 15; ++j) {
    const int joint_id = j + 1, digit = j / 3, k = j % 3;
    // The last joint's bone continues the one before it in the flat rest pose (a fingertip
    // vertex sits on the pad or the nail, off the bone's axis).
    const Eigen::Vector3d bone = k < 2 ? joint(joint_id + 1) - joint(joint_id) : joint(joint_id) - joint(joint_id - 1);
    Frame& f = frames_[static_cast<std::size_t>(j)];
    if (bone.norm() < 1e-6)
      throw Error(fmt::format("joint limits: the hand model's {} {} bone has no length", kDigit[static_cast<std::size_t>(digit)],
                              (digit == 4 ? kThumbJoint : kFingerJoint)[static_cast<std::size_t>(k)]));
    f.d = bone.normalized();
    Eigen::Vector3d a = f.d.cross(palm.normalized());
    if (a.norm() < 1e-6) a = f.d.unitOrthogonal();  // a bone along the palm normal (a thumb)
    f.a = a.normalized();
    f.ad = f.a.cross(f.d);
    f.thumb = digit == 4;
    const std::array<const JointLimit*, 3> finger{&limits.mcp, &limits.pip, &limits.dip};
    const std::array<const JointLimit*, 3> thumb{&limits.thumb_cmc, &limits.thumb_mcp, &limits.thumb_ip};
    f.limit = in_radians(*(f.thumb ? thumb : finger)[static_cast<std::size_t>(k)]);
  }
}

Eigen::Vector3d JointLimits::angles(int j, const Eigen::Vector3d& aa) const {
  if (j < 0 || j >= 15) throw Error("joint limits: joint " + std::to_string(j) + " is not a finger joint (0..14)");
  Eigen::Vector3d out;
  raw_angles(j, aa.data(), out.data());
  return out / kRad;
}

Eigen::Vector3d JointLimits::parameters(int j, const Eigen::Vector3d& aa) const {
  if (j < 0 || j >= 15) throw Error("joint limits: joint " + std::to_string(j) + " is not a finger joint (0..14)");
  const Frame& f = frames_[static_cast<std::size_t>(j)];
  Eigen::Vector3d b, angle;
  ceres::AngleAxisRotatePoint(aa.data(), f.d.data(), b.data());
  raw_angles(j, aa.data(), angle.data());  // the twist
  const double along = b.dot(f.d), side = b.dot(f.a), palm = b.dot(f.ad);
  return {std::atan2(palm, along), std::atan2(side, std::hypot(along, palm)), angle[2]};
}

std::array<AngleRange, 3> JointLimits::bounds(int j) const {
  const Frame& f = frames_.at(static_cast<std::size_t>(j));
  const JointLimit& L = f.limit;
  // Abduction within ±90°: beyond, (flex, abd) and (flex ± π, ±π − abd) are one bone.
  const double abduct = std::min(L.flex.hi, M_PI / 2);
  if (f.thumb) return {AngleRange{-L.flex.hi, L.flex.hi}, AngleRange{-abduct, abduct}, L.twist};
  return {L.flex, L.abduct, L.twist};
}

bool JointLimits::clamp(int j, Eigen::Vector3d* aa) const {
  const Frame& f = frames_.at(static_cast<std::size_t>(j));
  Eigen::Vector3d angle;
  raw_angles(j, aa->data(), angle.data());
  const JointLimit& L = f.limit;
  const auto in = [](double x, const AngleRange& r) { return std::clamp(x, r.lo, r.hi); };
  Eigen::Vector3d c(in(angle[0], L.flex), f.thumb ? 0.0 : in(angle[1], L.abduct), in(angle[2], L.twist));
  if (f.thumb) c[1] = angle[1];
  if ((c - angle).cwiseAbs().maxCoeff() < 1e-12) return false;
  // The bone's direction at the clamped angles.
  Eigen::Vector3d bone;
  if (f.thumb) {
    // Swing clamped, in the plane of the current swing.
    Eigen::Vector3d b;
    ceres::AngleAxisRotatePoint(aa->data(), f.d.data(), b.data());
    Eigen::Vector3d across = b - b.dot(f.d) * f.d;
    if (across.norm() < 1e-12) across = f.a;
    bone = std::cos(c[0]) * f.d + std::sin(c[0]) * across.normalized();
  } else {
    bone = std::cos(c[1]) * (std::cos(c[0]) * f.d + std::sin(c[0]) * f.ad) + std::sin(c[1]) * f.a;
  }
  const Eigen::Quaterniond swing = Eigen::Quaterniond::FromTwoVectors(f.d, bone);
  const Eigen::Quaterniond twist(Eigen::AngleAxisd(c[2], f.d));
  const Eigen::AngleAxisd r(swing * twist);
  *aa = r.angle() * r.axis();
  return true;
}

int JointLimits::clamp_pose(double* pose) const {
  int moved = 0;
  for (int j = 0; j < 15; ++j) {
    Eigen::Vector3d aa(pose[3 * j], pose[3 * j + 1], pose[3 * j + 2]);
    if (!clamp(j, &aa)) continue;
    for (int k = 0; k < 3; ++k) pose[3 * j + k] = aa[k];
    ++moved;
  }
  return moved;
}

double JointLimits::largest_excess(const Eigen::VectorXd& pose, std::string* where) const {
  if (pose.size() != HandModel::kPoseDim)
    throw Error("joint limits: a finger pose has 45 values, got " + std::to_string(pose.size()));
  double worst = 0;
  for (int j = 0; j < 15; ++j) {
    double r[3];
    excess(j, pose.data() + 3 * j, r);
    for (int c = 0; c < 3; ++c) {
      if (r[c] / kRad <= worst) continue;
      worst = r[c] / kRad;
      if (where) {
        const int digit = j / 3, k = j % 3;
        const bool thumb = digit == 4;
        const char* what = c == 0 ? (thumb ? "swing" : "flexion") : (c == 1 ? "abduction" : "twist");
        *where = fmt::format("{} {} {} {:.0f}° outside its range", kDigit[static_cast<std::size_t>(digit)],
                             (thumb ? kThumbJoint : kFingerJoint)[static_cast<std::size_t>(k)], what, worst);
      }
    }
  }
  return worst;
}

}  // namespace bimart
