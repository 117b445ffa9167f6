#include "core/synth/trajectory.h"

#include <algorithm>
#include <cmath>

#include <ATen/ATen.h>
#include <Eigen/Geometry>

#include "core/geometry/rotation.h"
#include "core/synth/motion_table.h"
#include "core/util/error.h"
#include "core/util/random.h"

namespace bimart {
namespace {

// A pose the object moves to, and how: `frames` to get there, then `hold` frames still.
struct Key {
  double angle = 0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  int frames = 0;
  int hold = 0;
};

ObjectState state_of(const Key& k) {
  ObjectState s;
  s.angle = k.angle;
  s.root_rotation = matrix_to_axis_angle(k.rotation.toRotationMatrix());
  s.root_translation = k.translation;
  return s;
}

double sample(Rng& rng, const MotionRange& r) { return rng.uniform(r.min, std::max(r.min, r.max)); }
double signed_sample(Rng& rng, const MotionRange& r) { return (rng.chance(0.5) ? 1 : -1) * sample(rng, r); }

Eigen::Quaterniond yawed(const Eigen::Quaterniond& q, double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())) * q;
}

}  // namespace

const char* kind_name(SequenceKind kind) { return kind == SequenceKind::Grab ? "grab" : "use"; }

double min_jerk(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10 + u * (-15 + 6 * u));
}

at::Tensor Trajectory::tensor() const {
  at::Tensor t = at::empty({num_frames(), 7}, at::kFloat);
  float* p = t.data_ptr<float>();
  for (int f = 0; f < num_frames(); ++f) {
    const auto row = states[f].to_row();
    for (int k = 0; k < 7; ++k) p[7 * f + k] = static_cast<float>(row[k]);
  }
  return t;
}

Eigen::Matrix3d resting_rotation(const ArticulatedObject& object, double yaw) {
  const CategoryMotion& m = category_motion(object.category);
  const Eigen::Matrix3d up = rotation_between(m.up, Eigen::Vector3d::UnitY());
  const Eigen::Vector3d f = up * m.front;
  const double face = std::atan2(f.x(), f.z());  // yaw that turns `front` onto +z is -face
  return rotation_about(Eigen::Vector3d::UnitY(), yaw - face) * up;
}

double resting_height(const ArticulatedObject& object, const Eigen::Matrix3d& rotation, double angle) {
  const PosedObject p = pose_canonical(object, angle);
  double lo = std::numeric_limits<double>::infinity();
  for (const PartVertices* v : {&p.top, &p.bottom})
    for (Eigen::Index i = 0; i < v->rows(); ++i) lo = std::min(lo, (rotation * v->row(i).transpose()).y());
  return -lo;
}

Trajectory plan_trajectory(const ArticulatedObject& object, SequenceKind kind, std::uint64_t seed,
                           const TrajectoryOptions& options) {
  if (options.fps <= 0 || options.min_frames < 60 || options.max_frames < options.min_frames)
    throw Error("trajectory options: need fps > 0 and 60 <= min_frames <= max_frames");
  const CategoryMotion& m = category_motion(object.category);
  Rng rng(seed);
  const double range = object.angle_max - object.angle_min;
  const auto hinge = [&](double fraction) {
    return std::clamp(object.angle_min + fraction * range, object.angle_min, object.angle_max);
  };

  // Start: at rest on the table, turned a little, near the origin.
  Key rest;
  rest.angle = object.angle_min;
  if (kind == SequenceKind::Grab) rest.angle = hinge(sample(rng, m.grab_angle));
  else if (rng.chance(m.hold_open)) rest.angle = hinge(sample(rng, m.open));
  const Eigen::Matrix3d r0 = resting_rotation(object, rng.uniform(-0.6, 0.6));
  rest.rotation = Eigen::Quaterniond(r0);
  rest.translation = Eigen::Vector3d(rng.uniform(-0.05, 0.05), 0, rng.uniform(-0.05, 0.05));
  rest.translation.y() = resting_height(object, r0, rest.angle) + m.support;

  std::vector<Key> keys;  // after `rest`
  auto seg = [&](int lo, int hi) { return rng.integer(lo, hi); };
  auto lifted = [&](const Key& from) {
    Key k = from;
    k.translation.y() += sample(rng, m.lift);
    const Eigen::Vector3d axis(rng.uniform(-1, 1), 0, rng.uniform(-1, 1));
    if (axis.norm() > 1e-3 && m.tilt.max > 0)
      k.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(signed_sample(rng, m.tilt), axis.normalized())) * k.rotation;
    k.rotation = yawed(k.rotation, 0.5 * signed_sample(rng, m.turn));
    k.frames = seg(25, 45);
    k.hold = seg(0, 8);
    return k;
  };
  // Back on the table where it is now (horizontally), upright, at the current yaw.
  auto put_down = [&](const Key& from, const Key& upright) {
    Key k = from;
    const Eigen::Vector3d f = from.rotation * (upright.rotation.inverse() * Eigen::Vector3d::UnitZ());
    const double yaw = std::atan2(f.x(), f.z());
    k.rotation = yawed(upright.rotation, yaw);
    k.translation.y() = resting_height(object, k.rotation.toRotationMatrix(), k.angle) + m.support;
    k.frames = seg(25, 45);
    k.hold = 0;
    return k;
  };

  if (kind == SequenceKind::Grab) {
    Key up = lifted(rest);
    keys.push_back(up);
    Key carry = up;
    const double dir = rng.uniform(0, 2 * M_PI), dist = sample(rng, m.carry);
    carry.translation += Eigen::Vector3d(dist * std::cos(dir), rng.uniform(-0.03, 0.05), 0.6 * dist * std::sin(dir));
    carry.rotation = yawed(carry.rotation, 0.5 * signed_sample(rng, m.turn));
    if (m.tilt.max > 0 && rng.chance(0.5))
      carry.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(signed_sample(rng, m.tilt), Eigen::Vector3d::UnitX())) *
                       carry.rotation;
    carry.frames = seg(30, 60);
    carry.hold = seg(0, 10);
    keys.push_back(carry);
    if (rng.chance(0.35)) {  // one more turn in the air
      Key turn = carry;
      turn.rotation = yawed(turn.rotation, signed_sample(rng, m.turn));
      turn.frames = seg(25, 50);
      turn.hold = seg(0, 8);
      keys.push_back(turn);
    }
    keys.push_back(put_down(keys.back(), rest));
  } else {
    const bool in_air = rng.chance(m.use_in_air);
    const bool slide = !in_air && rng.chance(m.use_root_motion);
    Key cur = rest;
    if (in_air) {
      cur = lifted(rest);
      keys.push_back(cur);
    }
    const double open_angle = hinge(sample(rng, m.open));
    const bool starts_open = rest.angle > object.angle_min + 0.25 * range;
    std::vector<double> targets;
    if (starts_open) {
      targets.push_back(hinge(rng.chance(0.7) ? m.close.min : sample(rng, m.close)));
      if (rng.chance(0.3)) targets.push_back(open_angle);
    } else {
      targets.push_back(open_angle);
      if (rng.chance(0.75)) targets.push_back(hinge(rng.chance(0.7) ? m.close.min : sample(rng, m.close)));
      if (targets.size() == 2 && rng.chance(0.25)) targets.push_back(hinge(sample(rng, m.open)));
    }
    for (size_t i = 0; i < targets.size(); ++i) {
      Key k = cur;
      k.angle = targets[i];
      k.frames = seg(30, 60);
      k.hold = seg(0, 15);
      if (slide && i == 0) {
        k.rotation = yawed(k.rotation, signed_sample(rng, MotionRange{0.15, 0.5}));
        k.translation += Eigen::Vector3d(rng.uniform(-0.08, 0.08), 0, rng.uniform(-0.08, 0.08));
        k.translation.y() = resting_height(object, k.rotation.toRotationMatrix(),
                                           std::min(k.angle, cur.angle)) + m.support;
      }
      if (!in_air) {  // stays on the table at every angle it passes through
        k.translation.y() = std::max(resting_height(object, k.rotation.toRotationMatrix(), k.angle),
                                     resting_height(object, k.rotation.toRotationMatrix(), cur.angle)) +
                            m.support;
      }
      keys.push_back(k);
      cur = k;
    }
    if (in_air) keys.push_back(put_down(cur, rest));
  }

  // Frame budget: approach and release with the object still, then the segments, scaled
  // to fit [min_frames, max_frames].
  const double fps_scale = options.fps / 30.0;
  const int approach = static_cast<int>(std::lround(rng.integer(24, 40) * fps_scale));
  const int release = static_cast<int>(std::lround(rng.integer(24, 40) * fps_scale));
  const int pre = rng.integer(3, 8), post = rng.integer(3, 8);
  int motion = 0;
  for (const Key& k : keys) motion += k.frames + k.hold;
  const int fixed = approach + pre + post + release + 1;
  const int wanted = std::clamp(static_cast<int>(std::lround(fixed + motion * fps_scale)), options.min_frames,
                                options.max_frames);
  const double scale = std::max(0.2, static_cast<double>(wanted - fixed) / std::max(1, motion));
  for (Key& k : keys) {
    k.frames = std::max(8, static_cast<int>(std::lround(k.frames * scale)));
    k.hold = static_cast<int>(std::lround(k.hold * scale));
  }

  Trajectory t;
  t.kind = kind;
  t.fps = options.fps;
  for (int f = 0; f < approach + pre; ++f) t.states.push_back(state_of(rest));
  t.first_move = static_cast<int>(t.states.size()) - 1;
  Key from = rest;
  for (size_t i = 0; i < keys.size(); ++i) {
    const Key& to = keys[i];
    for (int f = 1; f < to.frames; ++f) {
      const double s = min_jerk(static_cast<double>(f) / to.frames);
      Key k;
      k.angle = from.angle + s * (to.angle - from.angle);
      k.rotation = from.rotation.slerp(s, to.rotation);
      k.translation = from.translation + s * (to.translation - from.translation);
      t.states.push_back(state_of(k));
    }
    t.states.push_back(state_of(to));  // exactly the key (slerp at 1 may differ in the last bit)
    for (int f = 0; f < (i + 1 < keys.size() ? to.hold : 0); ++f) t.states.push_back(state_of(to));
    from = to;
  }
  // The last frame of the motion reached `from`; the object is still from here on.
  t.last_move = static_cast<int>(t.states.size()) - 2;
  while (t.num_frames() < wanted) t.states.push_back(state_of(from));
  if (t.num_frames() > options.max_frames) {
    // Segments have a floor of 8 frames; trim the release (never the motion).
    t.states.resize(static_cast<size_t>(std::max(options.max_frames, t.last_move + 2 + post + 12)));
  }
  return t;
}

}  // namespace bimart
