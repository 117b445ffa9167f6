// Keyframe interpolation: values at the keys, C² smoothness, unit rotations, rest at the ends.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "core/geometry/euler.h"
#include "core/geometry/rotation.h"
#include "core/trajectory/cubic_spline.h"
#include "core/trajectory/keyframes.h"
#include "core/trajectory/rotation_spline.h"

namespace bimart {
namespace {

constexpr double kDeg = M_PI / 180;

double second_derivative(const CubicSpline& s, double t, double h = 1e-4) {
  return (s(t + h) - 2 * s(t) + s(t - h)) / (h * h);
}

TEST(CubicSpline, HitsKnotsAndIsC2AtThem) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> t = {0, 0.4, 1.1, 1.5, 2.7, 3.0}, y;
  for (std::size_t i = 0; i < t.size(); ++i) y.push_back(u(rng));
  for (auto end : {CubicSpline::End::Clamped, CubicSpline::End::Natural}) {
    const CubicSpline s(t, y, end);
    for (std::size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(s(t[i]), y[i], 1e-12);
    for (std::size_t i = 1; i + 1 < t.size(); ++i) {
      // One-sided second derivatives just left and right of the knot agree.
      const double left = second_derivative(s, t[i] - 2e-3, 1e-3), right = second_derivative(s, t[i] + 2e-3, 1e-3);
      EXPECT_NEAR(left, right, 0.05 * (std::abs(left) + 1)) << "knot " << i;
      // The first derivative is continuous too.
      EXPECT_NEAR(s.derivative(t[i] - 1e-7), s.derivative(t[i] + 1e-7), 1e-5);
    }
  }
  const CubicSpline clamped(t, y, CubicSpline::End::Clamped), natural(t, y, CubicSpline::End::Natural);
  EXPECT_NEAR(clamped.derivative(t.front()), 0, 1e-12);
  EXPECT_NEAR(clamped.derivative(t.back()), 0, 1e-12);
  EXPECT_NEAR(second_derivative(natural, t.front() + 1e-3, 1e-4), 0, 0.05);
  EXPECT_GT(std::abs(natural.derivative(t.front())), 0.05);  // natural ends move
  // Outside the knots: held when at rest, continued linearly when natural.
  EXPECT_NEAR(clamped(-1), y.front(), 1e-12);
  EXPECT_NEAR(natural(t.back() + 1) - natural(t.back()), natural.derivative(t.back()), 1e-9);
}

TEST(CubicSpline, ReproducesACubicWithMatchingEndSlopes) {
  // A clamped spline with the true end slopes reproduces any cubic exactly.
  auto f = [](double x) { return 0.3 * x * x * x - x * x + 0.5 * x + 2; };
  auto df = [](double x) { return 0.9 * x * x - 2 * x + 0.5; };
  const std::vector<double> t = {-1, 0, 0.5, 2, 3};
  std::vector<double> y;
  for (double x : t) y.push_back(f(x));
  const CubicSpline s(t, y, CubicSpline::End::Clamped, df(-1), df(3));
  for (double x = -1; x <= 3; x += 0.137) EXPECT_NEAR(s(x), f(x), 1e-10) << x;
}

// Keys on the frame grid of 120 fps: position, angle and rotation in various combinations.
std::vector<Keyframe> sample_keys() {
  std::vector<Keyframe> k(4);
  k[0].t = 0;
  k[0].position = Eigen::Vector3d(0, 0, 0);
  k[0].angle = 0;
  k[0].rotation = Eigen::Quaterniond::Identity();
  k[1].t = 0.5;
  k[1].position = Eigen::Vector3d(0.1, 0.3, -0.05);
  k[1].rotation = Eigen::Quaterniond(euler_to_matrix("xyz", Eigen::Vector3d(20, -30, 45) * kDeg));
  k[2].t = 1.25;
  k[2].angle = 60 * kDeg;  // position and rotation missing: interpolated
  k[3].t = 2.0;
  k[3].position = Eigen::Vector3d(0.2, 0.1, 0.1);
  k[3].angle = 90 * kDeg;
  k[3].rotation = Eigen::Quaterniond(euler_to_matrix("zyx", Eigen::Vector3d(120, 10, -20) * kDeg));
  for (int i = 0; i < 4; ++i) k[i].line = 10 + 4 * i;
  return k;
}

Eigen::Matrix3d frame_rotation(const Trajectory& tr, Eigen::Index f) {
  return axis_angle_to_matrix(tr.states.block<1, 3>(f, 1).transpose());
}

TEST(Keyframes, HitTheKeysAndRotationsStayRotations) {
  const auto keys = sample_keys();
  Trajectory tr;
  sample_keyframes(keys, 120, true, "k.yaml", tr);
  ASSERT_EQ(tr.num_frames(), 241);
  EXPECT_EQ(tr.fps, 120);
  for (const Keyframe& k : keys) {
    const Eigen::Index f = std::lround(k.t * 120);
    if (k.position) EXPECT_LT((tr.states.block<1, 3>(f, 4).transpose() - *k.position).norm(), 1e-9) << k.t;
    if (k.angle) EXPECT_NEAR(tr.states(f, 0), *k.angle, 1e-9) << k.t;
    if (k.rotation) {
      const double err = Eigen::AngleAxisd(frame_rotation(tr, f).transpose() * k.rotation->toRotationMatrix()).angle();
      EXPECT_LT(err, 1e-9) << k.t;
    }
  }
  // Every frame's rotation is orthonormal with det 1, and the spline gives unit quaternions.
  const RotationSpline spline({0, 0.5, 2.0}, {*keys[0].rotation, *keys[1].rotation, *keys[3].rotation},
                              CubicSpline::End::Clamped);
  for (double t = -0.5; t <= 2.5; t += 0.01) EXPECT_NEAR(spline(t).norm(), 1.0, 1e-12);
  for (Eigen::Index f = 0; f < tr.num_frames(); ++f) {
    const Eigen::Matrix3d r = frame_rotation(tr, f);
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  }
}

// Largest change of the second difference of column c across a key frame, and away from keys.
std::pair<double, double> jerk_at_and_off_keys(const Trajectory& tr, const std::vector<Eigen::Index>& key_frames,
                                               const std::function<double(Eigen::Index)>& value) {
  auto d2 = [&](Eigen::Index f) { return value(f + 1) - 2 * value(f) + value(f - 1); };
  double at = 0, off = 0;
  for (Eigen::Index f = 2; f + 2 < tr.num_frames(); ++f) {
    const double j = std::abs(d2(f + 1) - d2(f));
    bool near = false;
    for (Eigen::Index k : key_frames) near = near || (f >= k - 1 && f <= k);
    (near ? at : off) = std::max(near ? at : off, j);
  }
  return {at, off};
}

TEST(Keyframes, SecondDifferencesAreContinuousAcrossKeys) {
  const auto keys = sample_keys();
  Trajectory tr;
  sample_keyframes(keys, 120, true, "k.yaml", tr);
  const std::vector<Eigen::Index> interior = {60, 150};  // t = 0.5 and 1.25
  for (int c : {0, 4, 5, 6}) {
    const auto [at, off] = jerk_at_and_off_keys(tr, interior, [&](Eigen::Index f) { return tr.states(f, c); });
    // C²: the second difference changes at a key by a third-order amount like anywhere else;
    // a jump in acceleration (C¹ only) would be ~ acceleration * dt² (many times larger).
    EXPECT_LT(at, 2.0 * off + 1e-12) << "column " << c;
  }
  for (int r = 0; r < 9; ++r) {
    const auto [at, off] = jerk_at_and_off_keys(
        tr, interior, [&](Eigen::Index f) { return frame_rotation(tr, f)(r / 3, r % 3); });
    EXPECT_LT(at, 2.0 * off + 1e-12) << "rotation entry " << r;
  }
  // And bounded: the largest acceleration of the position stays near what the keys ask for.
  double max_d2 = 0;
  for (Eigen::Index f = 1; f + 1 < tr.num_frames(); ++f)
    max_d2 = std::max(max_d2, (tr.states.row(f + 1) - 2 * tr.states.row(f) + tr.states.row(f - 1))
                                  .segment<3>(4)
                                  .norm());
  EXPECT_LT(max_d2 * 120 * 120, 10.0);  // m/s²
}

TEST(Keyframes, ChecksTheSmoothnessTestCanFail) {
  // A curve with a jump in acceleration at t = 1 (two parabolas) fails the same criterion.
  Trajectory tr;
  tr.states.setZero(241, 7);
  for (Eigen::Index f = 0; f < 241; ++f) {
    const double t = f / 120.0;
    tr.states(f, 4) = t < 1 ? t * t : 1 + 2 * (t - 1) - 3 * (t - 1) * (t - 1);
  }
  const auto [at, off] = jerk_at_and_off_keys(tr, {120}, [&](Eigen::Index f) { return tr.states(f, 4); });
  EXPECT_GT(at, 2.0 * off + 1e-12);
}

TEST(Keyframes, RestAtTheEndsUnlessToldOtherwise) {
  const auto keys = sample_keys();
  for (bool rest : {true, false}) {
    Trajectory tr;
    sample_keyframes(keys, 120, rest, "k.yaml", tr);
    const Eigen::Index n = tr.num_frames();
    auto step = [&](Eigen::Index f) { return (tr.states.row(f) - tr.states.row(f - 1)).norm(); };
    // From rest the steps grow like 1, 3, 5, ... (zero velocity, constant acceleration); at
    // a speed they stay about equal (natural ends: zero acceleration).
    const double start = step(1) / step(2), end = step(n - 1) / step(n - 2);
    if (rest) {
      EXPECT_NEAR(start, 1.0 / 3, 0.05);
      EXPECT_NEAR(end, 1.0 / 3, 0.05);
    } else {
      EXPECT_NEAR(start, 1.0, 0.05);
      EXPECT_NEAR(end, 1.0, 0.05);
    }
  }
}

TEST(Keyframes, ChannelsHoldOutsideTheirKeys) {
  std::vector<Keyframe> k(3);
  k[0].t = 0;
  k[0].position = Eigen::Vector3d(0, 0, 0);
  k[1].t = 1;
  k[1].angle = 0.2;
  k[2].t = 2;
  k[2].angle = 1.0;
  k[2].position = Eigen::Vector3d(1, 0, 0);
  Trajectory tr;
  sample_keyframes(k, 30, true, "k.yaml", tr);
  ASSERT_EQ(tr.num_frames(), 61);
  for (Eigen::Index f = 0; f <= 30; ++f) EXPECT_DOUBLE_EQ(tr.states(f, 0), 0.2);  // before its first key
  EXPECT_NEAR(tr.states(60, 0), 1.0, 1e-12);
  for (Eigen::Index f = 0; f < 61; ++f) EXPECT_LT((tr.states.block<1, 3>(f, 1).norm()), 1e-15);  // no rotation key
  // A key time off the frame grid: frames stop at the last whole frame.
  k[2].t = 2.01;
  sample_keyframes(k, 30, true, "k.yaml", tr);
  EXPECT_EQ(tr.num_frames(), 61);
}

TEST(Keyframes, FullTurnsStayContinuous) {
  // Four keys a third of a turn apart about z: one full turn, axis-angle without a jump.
  std::vector<Keyframe> k(4);
  for (int i = 0; i < 4; ++i) {
    k[i].t = i;
    k[i].rotation = Eigen::Quaterniond(Eigen::AngleAxisd(i * 2 * M_PI / 3, Eigen::Vector3d::UnitZ()));
  }
  Trajectory tr;
  sample_keyframes(k, 30, true, "k.yaml", tr);
  for (Eigen::Index f = 1; f < tr.num_frames(); ++f)
    EXPECT_LT((tr.states.block<1, 3>(f, 1) - tr.states.block<1, 3>(f - 1, 1)).norm(), 0.2) << f;
  EXPECT_NEAR(tr.states(tr.num_frames() - 1, 3), 2 * M_PI, 1e-9);
}

TEST(Rotation, EulerOrdersTurnAboutFixedAxes) {
  const Eigen::Matrix3d r = euler_to_matrix("xyz", Eigen::Vector3d(90, 0, 90) * kDeg);
  // x by 90 then (world) z by 90: the y axis goes to z, then stays; x goes to y.
  EXPECT_LT((r * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_LT((r * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  const Eigen::Vector3d a(0.3, -0.7, 1.1);
  const Eigen::Matrix3d zyx = euler_to_matrix("zyx", a);
  const Eigen::Matrix3d expect = (Eigen::AngleAxisd(a[2], Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(a[1], Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(a[0], Eigen::Vector3d::UnitZ()))
                                     .toRotationMatrix();
  EXPECT_LT((zyx - expect).norm(), 1e-12);
  EXPECT_TRUE(is_euler_order("zxz"));
  EXPECT_FALSE(is_euler_order("xxy"));
  EXPECT_FALSE(is_euler_order("xyw"));
}

TEST(Rotation, UnwrapPicksTheClosestEquivalent) {
  const Eigen::Vector3d prev(0, 0, 3.1);
  const Eigen::Vector3d v(0, 0, -3.1);  // the same as 2π - 3.1 about +z
  EXPECT_LT((unwrap_axis_angle(v, prev) - Eigen::Vector3d(0, 0, 2 * M_PI - 3.1)).norm(), 1e-12);
  EXPECT_LT((unwrap_axis_angle(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 6.2, 0)) -
             Eigen::Vector3d(0, 2 * M_PI, 0))
                .norm(),
            1e-12);
  EXPECT_EQ(unwrap_axis_angle(Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d::Zero()), Eigen::Vector3d(0.1, 0, 0));
}

}  // namespace
}  // namespace bimart
