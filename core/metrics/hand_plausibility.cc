#include "core/metrics/hand_plausibility.h"

#include <ATen/ATen.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/squared_distance_3.h>
#include <Eigen/Geometry>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace bimart {
namespace {

using K = CGAL::Simple_cartesian<double>;
using V3 = Eigen::Vector3d;

constexpr double kDeg = 180.0 / M_PI;
// MANO joint order: wrist; index 1-3, middle 1-3, pinky 1-3, ring 1-3, thumb 1-3. Fingertip
// rows: thumb, index, middle, ring, pinky.
constexpr std::array<const char*, 5> kNames{"index", "middle", "pinky", "ring", "thumb"};
constexpr std::array<int, 5> kFirstJoint{1, 4, 7, 10, 13};
constexpr std::array<int, 5> kTip{1, 2, 4, 3, 0};

// The angle (degrees) from u to v about `axis`, both projected onto the plane normal to it.
double turn_about(const V3& u, const V3& v, const V3& axis) {
  const V3 pu = u - u.dot(axis) * axis, pv = v - v.dot(axis) * axis;
  return std::atan2(pu.cross(pv).dot(axis), pu.dot(pv)) * kDeg;
}

std::string outside(const char* finger, const char* joint, const char* what, double angle, const JointRange& r) {
  if (angle >= r.lo && angle <= r.hi) return "";
  return fmt::format("{} {} {} {:.0f}° (range {:.0f} to {:.0f})", finger, joint, what, angle, r.lo, r.hi);
}

}  // namespace

std::string implausibility(const Eigen::Matrix<double, 16, 3>& J, const Eigen::Matrix<double, 5, 3>& tips, int hand) {
  const auto joint = [&](int i) -> V3 { return J.row(i).transpose(); };
  const auto tip = [&](int f) -> V3 { return tips.row(kTip[static_cast<std::size_t>(f)]).transpose(); };
  // The hand's axes: lateral (pinky to index), along the fingers, the palm normal; flexion is
  // + towards the palm (the left hand is the right's mirror image, so its lateral turn is −).
  const V3 lateral = (joint(1) - joint(7)).normalized();
  const V3 along = (joint(4) - joint(0)).normalized();
  const double side = hand == 0 ? -1.0 : 1.0;
  const V3 flex_axis = side * lateral;
  const V3 palm = side * lateral.cross(along).normalized();
  const FingerLimits& L = kFingerLimits;
  // Each finger's chain: wrist (or the thumb's base), three joints, the tip.
  for (int f = 0; f < 5; ++f) {
    const int j0 = kFirstJoint[static_cast<std::size_t>(f)];
    const V3 base = f == 4 ? joint(j0) : joint(0);
    const std::array<V3, 4> p{f == 4 ? joint(j0) : joint(j0), joint(j0 + 1), joint(j0 + 2), tip(f)};
    const char* name = kNames[static_cast<std::size_t>(f)];
    if (f == 4) {  // thumb: unsigned bends at MCP (p1) and IP (p2)
      const V3 b0 = (p[1] - p[0]).normalized(), b1 = (p[2] - p[1]).normalized(), b2 = (p[3] - p[2]).normalized();
      const double mcp = std::acos(std::clamp(b0.dot(b1), -1.0, 1.0)) * kDeg;
      const double ip = std::acos(std::clamp(b1.dot(b2), -1.0, 1.0)) * kDeg;
      if (mcp > L.thumb_mcp) return fmt::format("thumb MCP bent {:.0f}° (at most {:.0f})", mcp, L.thumb_mcp);
      if (ip > L.thumb_ip) return fmt::format("thumb IP bent {:.0f}° (at most {:.0f})", ip, L.thumb_ip);
      continue;
    }
    const V3 meta = (p[0] - base).normalized();  // wrist to knuckle
    const V3 b0 = (p[1] - p[0]).normalized(), b1 = (p[2] - p[1]).normalized(), b2 = (p[3] - p[2]).normalized();
    // Abduction: the bone's angle out of its flexion plane (the plane through the metacarpal
    // and the palm normal). Read about the palm normal instead, it is ill-conditioned for a
    // finger flexed towards the palm (80° flexion with 10° of abduction read 45°).
    const V3 across = (palm.cross(meta)).normalized();
    const double abduction = std::asin(std::clamp(b0.dot(across), -1.0, 1.0)) * kDeg;
    for (const std::string& why :
         {outside(name, "MCP", "flexion", turn_about(meta, b0, flex_axis), L.mcp_flex),
          outside(name, "MCP", "abduction", abduction, L.mcp_abduct),
          outside(name, "PIP", "flexion", turn_about(b0, b1, flex_axis), L.pip_flex),
          outside(name, "DIP", "flexion", turn_about(b1, b2, flex_axis), L.dip_flex)})
      if (!why.empty()) return why;
  }
  // Crossed fingers: bone segments of two different fingers too close.
  std::array<std::array<K::Segment_3, 3>, 5> bones;
  for (int f = 0; f < 5; ++f) {
    const int j0 = kFirstJoint[static_cast<std::size_t>(f)];
    const std::array<V3, 4> p{joint(j0), joint(j0 + 1), joint(j0 + 2), tip(f)};
    for (int b = 0; b < 3; ++b)
      bones[static_cast<std::size_t>(f)][static_cast<std::size_t>(b)] =
          K::Segment_3(K::Point_3(p[b].x(), p[b].y(), p[b].z()), K::Point_3(p[b + 1].x(), p[b + 1].y(), p[b + 1].z()));
  }
  for (int f = 0; f < 5; ++f)
    for (int g = f + 1; g < 5; ++g)
      for (const auto& s : bones[static_cast<std::size_t>(f)])
        for (const auto& t : bones[static_cast<std::size_t>(g)])
          if (CGAL::squared_distance(s, t) < kCrossedGap * kCrossedGap)
            return fmt::format("{} and {} cross", kNames[static_cast<std::size_t>(f)], kNames[static_cast<std::size_t>(g)]);
  return "";
}

FrameCount implausible_frames(const at::Tensor& vertices_in, const std::array<const HandModel*, 2>& models,
                              std::string* first_reason) {
  const at::Tensor v = vertices_in.to(at::kDouble).contiguous();
  if (v.dim() != 4 || v.size(0) != 2 || v.size(3) != 3)
    throw Error("hand plausibility: need vertices [2, N, V, 3], got " + c10::str(vertices_in.sizes()));
  const std::int64_t N = v.size(1), V = v.size(2);
  for (const HandModel* m : models)
    if (m == nullptr || m->j_regressor.cols() != V)
      throw Error("hand plausibility: the hand model has another vertex count than the hands (" + std::to_string(V) + ")");
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  FrameCount c;
  for (std::int64_t t = 0; t < N; ++t) {
    ++c.frames;
    for (int h = 0; h < 2; ++h) {
      const Eigen::Map<const Rows> x(v.data_ptr<double>() + ((h * N + t) * V) * 3, V, 3);
      const HandModel& m = *models[static_cast<std::size_t>(h)];
      const Eigen::Matrix<double, 16, 3> J = m.j_regressor * x;
      Eigen::Matrix<double, 5, 3> tips;
      for (int f = 0; f < 5; ++f) tips.row(f) = x.row(m.fingertips[static_cast<std::size_t>(f)]);
      const std::string why = implausibility(J, tips, h);
      if (why.empty()) continue;
      if (first_reason && first_reason->empty())
        *first_reason = fmt::format("frame {}, {} hand: {}", t, h == 0 ? "left" : "right", why);
      ++c.hits;
      break;
    }
  }
  return c;
}

}  // namespace bimart
