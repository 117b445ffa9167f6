// The refinement (core/refine/refinement.h) on cases with a known answer: a hand pushed
// into a box comes out, a jittery sequence comes out smoother.
#include "core/refine/refinement.h"
#include "core/metrics/hand_plausibility.h"

#include <limits>

#include <gtest/gtest.h>

#include <ATen/ATen.h>
#include <Eigen/Eigenvalues>

#include "core/features/hand_features.h"
#include "core/geometry/rotation.h"
#include "core/metrics/accel.h"
#include "core/object/families/primitives.h"
#include "core/refine/hand_state.h"
#include "core/refine/mano_fit.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "tests/refine/known_motion.h"
#include "tests/refine/test_objects.h"
#include "tests/synth/shipped_hands.h"

namespace bimart {
namespace {

// A 40 × 40 × 10 cm slab whose top face is z = 0 (bottom part) and a small lid far away.
ArticulatedObject slab() { return test::slab(); }

// Hand features X of keypoints H [2, N, 100, 3] (rows 0..99 are the keypoints).
at::Tensor keypoint_features(const at::Tensor& H, const ArticulatedObject& object, const at::Tensor& states) {
  std::vector<int> ids(100);
  for (int i = 0; i < 100; ++i) ids[i] = i;
  return hand_features(H, ids, object, states);
}

// Both hands lying flat on z = 0 (the thinnest direction of each flat hand turned to z),
// 1 mm above it, side by side; N identical frames.
HandMotion hands_on_the_slab(const std::array<const HandModel*, 2>& models, int N) {
  std::array<std::vector<double>, 2> states, betas;
  for (int h = 0; h < 2; ++h) {
    std::vector<double> x(51, 0.0);
    betas[h].assign(10, 0.0);
    HandMotion one = hand_motion_from_states({x, x}, {betas[h], betas[h]}, 1);
    at::Tensor v = pose_hand_vertices(models, one)[h][0].to(at::kDouble);
    const Eigen::Map<const Points3> V(v.data_ptr<double>(), v.size(0), 3);
    const Eigen::RowVector3d mean = V.colwise().mean();
    const Eigen::Matrix3d C = (V.rowwise() - mean).transpose() * (V.rowwise() - mean);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(C);
    const Eigen::Matrix3d R = rotation_between(eig.eigenvectors().col(0), Eigen::Vector3d::UnitZ());
    const Eigen::Vector3d aa = matrix_to_axis_angle(R);
    for (int k = 0; k < 3; ++k) x[k] = aa[k];
    one = hand_motion_from_states({x, x}, {betas[h], betas[h]}, 1);
    v = pose_hand_vertices(models, one)[h][0].to(at::kDouble);
    const at::Tensor lo = std::get<0>(v.min(0)), hi = std::get<0>(v.max(0));
    x[48] = (h == 0 ? -0.1 : 0.1) - 0.5 * (lo[0] + hi[0]).item<double>();
    x[49] = -0.5 * (lo[1] + hi[1]).item<double>();
    x[50] = 0.001 - lo[2].item<double>();
    states[h].clear();
    for (int t = 0; t < N; ++t) states[h].insert(states[h].end(), x.begin(), x.end());
  }
  HandMotion m = hand_motion_from_states(states, betas, N);
  m.vertices = pose_hand_vertices(models, m);
  return m;
}

std::vector<int> ids_of(const HandModel& m) { return model_keypoints(m); }

// A known motion (tests/refine/known_motion.h) lifted `height` (m): far from the slab.
HandMotion above_the_slab(const std::array<const HandModel*, 2>& models, int N, unsigned seed, float height) {
  HandMotion m = test::known_motion(models, N, seed);
  for (auto& p : m.hands) p.trans = p.trans + at::tensor({0.0f, 0.0f, height});
  m.vertices = pose_hand_vertices(models, m);
  return m;
}

// Hands on the slab (the truth) and a prediction of them `depth` (m) too deep: keypoints
// sunk, directions to the surface as they were; with its MANO fit.
struct PushedHands {
  at::Tensor states, X, pushed;
  HandMotion truth, fit;
};
PushedHands pushed_into_the_slab(const ArticulatedObject& object, int N, float depth) {
  const auto& models = test::shipped_hands();
  PushedHands c;
  c.states = at::zeros({N, 7}, at::kFloat);
  c.truth = hands_on_the_slab(models, N);
  c.X = hand_features(c.truth.vertices, ids_of(*models[1]), object, c.states);
  auto [H, D] = split_hand_features(c.X);
  c.pushed = join_hand_features(H - at::tensor({0.0f, 0.0f, depth}), D);
  c.fit = fit_mano(models, hand_features_to_world(c.pushed, c.states).positions);
  return c;
}

TEST(Refinement, AHandPushedIntoABoxComesOutAndKeepsToTheKeypoints) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = slab();
  const ObjectDistance distance(object);
  const int N = 6;
  const PushedHands c = pushed_into_the_slab(object, N, 0.015f);
  const at::Tensor &states = c.states, &X = c.X, &pushed = c.pushed;
  const HandMotion& fit = c.fit;

  RefineReport report;
  const HandMotion refined = refine_hands(models, distance, states, pushed, fit, {}, &report);
  std::printf("%s", format_refine_report(report).c_str());
  const at::Tensor true_kp = hand_features_to_world(X, states).positions.to(at::kDouble);
  for (int h = 0; h < 2; ++h) {
    EXPECT_GT(report.hands[h].max_depth_before, 0.012);
    EXPECT_LE(report.hands[h].max_depth_after, 0.002);
    EXPECT_LT(report.hands[h].after.total(), report.hands[h].before.total());
    const std::vector<int> ids = ids_of(*models[h]);
    const at::Tensor kp = refined.vertices[h].index_select(1, at::tensor(std::vector<int64_t>(ids.begin(), ids.end())));
    const double err = (kp.to(at::kDouble) - true_kp[h]).norm(2, {2}).mean().item<double>();
    EXPECT_LT(err, 0.005) << "hand " << h << ": mean keypoint error " << err * 1e3 << " mm";
  }
  // Every vertex of the result checked again, independently of the report.
  for (int t = 0; t < N; ++t)
    for (int h = 0; h < 2; ++h) {
      const at::Tensor v = refined.vertices[h][t].to(at::kDouble).contiguous();
      const Eigen::Map<const Points3> V(v.data_ptr<double>(), v.size(0), 3);
      EXPECT_LE(distance.max_signed_distance(ObjectState{}, V), 0.002);
    }
}

// The penetration term alone (no projection, keypoints left where they were predicted):
// the hand must still come out, to the tolerance.
TEST(Refinement, PenetrationAlonePushesAHandOut) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = slab();
  const ObjectDistance distance(object);
  const PushedHands c = pushed_into_the_slab(object, 4, 0.008f);
  RefineOptions o;
  o.w_proj = 0;
  RefineReport report;
  refine_hands(models, distance, c.states, c.pushed, c.fit, o, &report);
  std::printf("%s", format_refine_report(report).c_str());
  for (int h = 0; h < 2; ++h) {
    EXPECT_GT(report.hands[h].max_depth_before, 0.006);
    EXPECT_LE(report.hands[h].max_depth_after, o.pen_tolerance);
  }
}

// Finger pose held (w_pose): the hands pushed out of the slab by the penetration term alone
// keep their fingers nearer the fit's pose than without it — the hand moves instead — and
// still come out.
TEST(Refinement, HeldFingerPoseMovesTheHandInsteadOfTheFingers) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = slab();
  const ObjectDistance distance(object);
  const PushedHands c = pushed_into_the_slab(object, 4, 0.008f);
  const auto finger_change = [&](const HandMotion& m) {  // largest |θ − θ_fit| over finger parameters (rad)
    double worst = 0;
    for (int h = 0; h < 2; ++h)
      worst = std::max(worst, (m.hands[h].pose - c.fit.hands[h].pose).abs().max().item<double>());
    return worst;
  };
  RefineOptions o;
  o.w_proj = 0;
  RefineReport free_report, held_report;
  const double free_change = finger_change(refine_hands(models, distance, c.states, c.pushed, c.fit, o, &free_report));
  o.w_pose = 1e4;
  const double held_change = finger_change(refine_hands(models, distance, c.states, c.pushed, c.fit, o, &held_report));
  std::printf("largest finger change: free %.4f rad, held %.4f rad\n", free_change, held_change);
  EXPECT_LT(held_change, 0.5 * free_change);
  for (int h = 0; h < 2; ++h) {
    EXPECT_LE(held_report.hands[h].max_depth_after, o.pen_tolerance);
    EXPECT_GT(held_report.hands[h].after.pose, 0.0);  // the term is evaluated and reported
  }
}

// A part thinner than twice the depth: hands predicted 1.5 cm into a 2 cm slab have their
// deepest vertices nearer its underside. Pushed each to its nearest surface they split and
// stay stuck; pushed towards the rest of the hand (pen_exit_depth) they all leave on top.
TEST(Refinement, AHandSunkPastTheMiddleOfAThinPartLeavesOnItsOwnSide) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = test::slab(0.02);
  const ObjectDistance distance(object);
  const PushedHands c = pushed_into_the_slab(object, 4, 0.015f);
  RefineOptions exit, nearest;
  exit.w_proj = nearest.w_proj = 0;  // penetration alone, as above
  nearest.pen_exit_depth = std::numeric_limits<double>::infinity();
  RefineReport with, without;
  const HandMotion out = refine_hands(models, distance, c.states, c.pushed, c.fit, exit, &with);
  refine_hands(models, distance, c.states, c.pushed, c.fit, nearest, &without);
  std::printf("exit:\n%snearest:\n%s", format_refine_report(with).c_str(), format_refine_report(without).c_str());
  for (int h = 0; h < 2; ++h) {
    EXPECT_GT(with.hands[h].max_depth_before, 0.008);  // the middle of the slab is 1 cm deep
    EXPECT_LE(with.hands[h].max_depth_after, exit.pen_tolerance) << "hand " << h;
    EXPECT_GT(without.hands[h].max_depth_after, 2 * exit.pen_tolerance) << "hand " << h;
    // Out on top, where the hand came from, not through the underside.
    EXPECT_GT(out.vertices[h].select(2, 2).mean().item<double>(), 0.0) << "hand " << h;
  }
  // Every frame's way out averaged with its neighbours' (pen_exit_smooth): the same way here,
  // so the same result.
  RefineOptions smoothed = exit;
  smoothed.pen_exit_smooth = 2;
  RefineReport s;
  const HandMotion out_s = refine_hands(models, distance, c.states, c.pushed, c.fit, smoothed, &s);
  for (int h = 0; h < 2; ++h) {
    EXPECT_LE(s.hands[h].max_depth_after, exit.pen_tolerance) << "hand " << h;
    EXPECT_GT(out_s.vertices[h].select(2, 2).mean().item<double>(), 0.0) << "hand " << h;
  }
  nearest.pen_exit_depth = -1;
  EXPECT_THROW(nearest.validate(), Error);
  smoothed.pen_exit_smooth = -1;
  EXPECT_THROW(smoothed.validate(), Error);
}

// A hollow part: a closed box of 5 mm walls, its lid the top part (top face z = 0). Hands
// predicted 1.5 cm into it have their palms in the box: the lid holds at most 2.5 mm of
// them, so the signed distance barely sees it. With pen_cavities the vertices in the box
// leave through the lid, on top; without, the hands stay in the box.
TEST(Refinement, AHandThroughAHollowPartsWallLeavesThroughIt) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = test::hollow_box(0.3);  // both hands well inside the lid's edges
  const ObjectDistance distance(object);
  const PushedHands c = pushed_into_the_slab(object, 4, 0.015f);
  const auto deepest_cavity = [&](const HandMotion& m) {
    double worst = 0;
    for (int h = 0; h < 2; ++h)
      for (int t = 0; t < 4; ++t) {
        const at::Tensor v = m.vertices[h][t].to(at::kDouble).contiguous();
        worst = std::max(worst, distance.max_cavity_depth(ObjectState{}, Eigen::Map<const Points3>(v.data_ptr<double>(), v.size(0), 3)));
      }
    return worst;
  };
  RefineOptions with, without;
  with.w_proj = without.w_proj = 0;  // penetration alone, as above
  with.pen_cavities = true;
  with.max_outer_iterations = without.max_outer_iterations = 6;  // as the pipelines
  RefineReport r_with, r_without;
  log::setup(getenv("REFINE_DEBUG") ? 1 : 0);
  const HandMotion out = refine_hands(models, distance, c.states, c.pushed, c.fit, with, &r_with);
  const HandMotion in = refine_hands(models, distance, c.states, c.pushed, c.fit, without, &r_without);
  std::printf("with:\n%swithout:\n%s", format_refine_report(r_with).c_str(), format_refine_report(r_without).c_str());
  const double before = deepest_cavity(c.fit), after_with = deepest_cavity(out), after_without = deepest_cavity(in);
  std::printf("deepest in the box: fit %.1f mm, with %.1f mm, without %.1f mm\n", before * 1e3, after_with * 1e3,
              after_without * 1e3);
  EXPECT_GT(before, 0.006);
  EXPECT_GT(after_without, 0.006);
  EXPECT_EQ(after_with, 0.0);
  for (int h = 0; h < 2; ++h) {
    EXPECT_LE(r_with.hands[h].max_depth_after, with.pen_tolerance) << "hand " << h;
    EXPECT_GT(out.vertices[h].select(2, 2).min().item<double>(), -0.003) << "hand " << h;  // on the lid
  }
}

// Both hands standing on their fingertips through a thin slab (12 mm, a notebook's cover; top face z = 0): the
// middle fingertip `below` (m) under its bottom face, the palm above; N identical frames.
HandMotion fingers_through_the_slab(const std::array<const HandModel*, 2>& models, int N, double below) {
  std::array<std::vector<double>, 2> states, betas;
  for (int h = 0; h < 2; ++h) {
    std::vector<double> x(51, 0.0);
    betas[h].assign(10, 0.0);
    const auto posed = [&] {  // the hand's vertices at x
      const HandMotion one = hand_motion_from_states({x, x}, {betas[h], betas[h]}, 1);
      const at::Tensor v = pose_hand_vertices(models, one)[h][0].to(at::kDouble).contiguous();
      return Points3(Eigen::Map<const Points3>(v.data_ptr<double>(), v.size(0), 3));
    };
    const int tip = models[static_cast<size_t>(h)]->fingertips[2];
    Points3 V = posed();
    const Eigen::Vector3d along = (V.row(tip) - V.colwise().mean()).transpose().normalized();
    const Eigen::Vector3d aa = matrix_to_axis_angle(rotation_between(along, -Eigen::Vector3d::UnitZ()));
    for (int k = 0; k < 3; ++k) x[k] = aa[k];
    V = posed();
    x[48] = (h == 0 ? -0.1 : 0.1) - V(tip, 0);
    x[49] = -V(tip, 1);
    x[50] = -0.012 - below - V(tip, 2);
    states[h].clear();
    for (int t = 0; t < N; ++t) states[h].insert(states[h].end(), x.begin(), x.end());
  }
  HandMotion m = hand_motion_from_states(states, betas, N);
  m.vertices = pose_hand_vertices(models, m);
  return m;
}

// Fingers through a thin part, their tips 1 cm beyond it (the notebooks' failure in the
// fixed evaluation set): the inside vertices leave upwards, towards the palm, and the tips'
// nearest face, the bottom one, holds them below — the fingers stay across the part. With
// pen_fingers_through the tips come back through it with their fingers.
TEST(Refinement, FingersThroughAThinPartComeBackThroughItWhole) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = test::slab(0.012);
  const ObjectDistance distance(object);
  const int N = 4;
  const HandMotion start = fingers_through_the_slab(models, N, 0.01);
  const at::Tensor states = at::zeros({N, 7}, at::kFloat);
  const at::Tensor X = hand_features(start.vertices, ids_of(*models[1]), object, states);
  RefineOptions with, without;
  with.w_proj = without.w_proj = 0;  // penetration alone, as above
  with.max_outer_iterations = without.max_outer_iterations = 6;  // as the pipelines
  with.pen_fingers_through = true;
  RefineReport r_with, r_without;
  const HandMotion out = refine_hands(models, distance, states, X, start, with, &r_with);
  const HandMotion stuck = refine_hands(models, distance, states, X, start, without, &r_without);
  std::printf("with:\n%swithout:\n%s", format_refine_report(r_with).c_str(), format_refine_report(r_without).c_str());
  for (int h = 0; h < 2; ++h) {
    EXPECT_GT(r_with.hands[h].max_depth_before, 0.005) << "hand " << h;  // 6 mm: the slab's middle
    EXPECT_LE(r_with.hands[h].max_depth_after, with.pen_tolerance) << "hand " << h;
    EXPECT_GT(r_without.hands[h].max_depth_after, with.pen_tolerance) << "hand " << h;  // 3.5 mm, boost 1e6
    // On top, where the palm is; without, the fingertips still under the slab.
    EXPECT_GT(out.vertices[h].select(2, 2).min().item<double>(), -0.003) << "hand " << h;
    EXPECT_LT(stuck.vertices[h].select(2, 2).min().item<double>(), -0.012) << "hand " << h;
  }
}

// The hold term: hands predicted 3 cm above the slab (no projection term, which would also
// bring them down). Where the object must be held, one hand comes onto it; elsewhere, and
// with w_hold = 0, both stay up.
TEST(Refinement, TheHoldTermPutsOneHandOnTheObjectWhereItMustBeHeld) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = slab();
  const ObjectDistance distance(object);
  const int N = 4;
  const PushedHands c = pushed_into_the_slab(object, N, -0.03f);
  const HeldFrames held{{true, true, false, false}, {}};
  RefineOptions o;
  o.w_proj = 0;
  const auto deepest = [&](const HandMotion& m, int h, int t) {
    const at::Tensor v = m.vertices[h][t].to(at::kDouble).contiguous();
    return distance.max_signed_distance(ObjectState{}, Eigen::Map<const Points3>(v.data_ptr<double>(), v.size(0), 3));
  };
  const HandMotion off = refine_hands(models, distance, c.states, c.pushed, c.fit, o, nullptr, held);
  for (int t = 0; t < N; ++t)
    for (int h = 0; h < 2; ++h) EXPECT_LT(deepest(off, h, t), -0.02) << "w_hold 0: hand " << h << ", frame " << t;
  o.w_hold = 1e5;
  RefineReport report;
  const HandMotion on = refine_hands(models, distance, c.states, c.pushed, c.fit, o, &report, held);
  std::printf("%s", format_refine_report(report).c_str());
  EXPECT_EQ(report.hands[0].held_frames + report.hands[1].held_frames, 2);
  for (int t = 0; t < 2; ++t) {
    const double a = deepest(on, 0, t), b = deepest(on, 1, t);
    EXPECT_GT(std::max(a, b), -0.005) << "frame " << t << ": a hand touches (Con's test)";
    EXPECT_LE(std::max(a, b), o.pen_tolerance) << "frame " << t;
    EXPECT_LT(std::min(a, b), -0.02) << "frame " << t << ": only one hand is held";
  }
  EXPECT_THROW(refine_hands(models, distance, c.states, c.pushed, c.fit, o, nullptr, HeldFrames{{true}, {}}), Error);
}

// A directed contact (`part:` in a hands file, RefineDirections::hold): hands 3 cm above the
// slab, nothing held by the object's motion; the left hand asked onto the slab (the bottom
// part) in frames 1-2 comes onto it there, the right stays up.
TEST(Refinement, ADirectedContactHoldsItsHandOnItsPart) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = slab();
  const ObjectDistance distance(object);
  const int N = 4;
  const PushedHands c = pushed_into_the_slab(object, N, -0.03f);
  RefineOptions o;
  o.w_proj = 0;
  o.w_hold = 1e5;
  RefineDirections asked;
  asked.hold[0] = {-1, static_cast<int>(ObjectPart::Bottom), static_cast<int>(ObjectPart::Bottom), -1};
  const auto deepest = [&](const HandMotion& m, int h, int t) {
    const at::Tensor v = m.vertices[h][t].to(at::kDouble).contiguous();
    return distance.max_signed_distance(ObjectState{}, Eigen::Map<const Points3>(v.data_ptr<double>(), v.size(0), 3));
  };
  RefineReport report;
  const HandMotion out = refine_hands(models, distance, c.states, c.pushed, c.fit, o, &report, HeldFrames{}, asked);
  std::printf("%s", format_refine_report(report).c_str());
  EXPECT_EQ(report.hands[0].held_frames, 2);
  EXPECT_EQ(report.hands[1].held_frames, 0);
  for (int t = 1; t <= 2; ++t) {
    EXPECT_GT(deepest(out, 0, t), -0.005) << "frame " << t << ": the left hand touches (Con's test)";
    EXPECT_LE(deepest(out, 0, t), o.pen_tolerance) << "frame " << t;
  }
  for (int t = 0; t < N; ++t) EXPECT_LT(deepest(out, 1, t), -0.02) << "frame " << t << ": the right hand stays up";
  asked.hold[0] = {-1, 3, -1, -1};
  EXPECT_THROW(refine_hands(models, distance, c.states, c.pushed, c.fit, o, nullptr, HeldFrames{}, asked), Error);
  asked.hold[0] = {-1, 0};
  EXPECT_THROW(refine_hands(models, distance, c.states, c.pushed, c.fit, o, nullptr, HeldFrames{}, asked), Error);
}

TEST(Refinement, AJitterySequenceComesOutSmoother) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = slab();
  const ObjectDistance distance(object);
  const int N = 20;
  // Hands well above the slab: only the acceleration and fit terms act.
  const HandMotion truth = above_the_slab(models, N, 21, 0.5f);
  const at::Tensor states = at::zeros({N, 7}, at::kFloat);
  at::Tensor H = test::noisy_keypoints(models, truth, 1.0, 22);
  at::Generator gen = at::detail::createCPUGenerator(23);
  H = H + at::normal(0.0, 0.004, {2, N, 1, 3}, gen);  // the whole hand jumps, frame to frame
  const at::Tensor X = keypoint_features(H, object, states);
  const HandMotion fit = fit_mano(models, H);
  RefineReport report;
  const HandMotion refined = refine_hands(models, distance, states, X, fit, {}, &report);
  std::printf("%s", format_refine_report(report).c_str());
  const double a_fit = mean_acceleration(fit.vertices), a_ref = mean_acceleration(refined.vertices);
  const double a_true = mean_acceleration(truth.vertices);
  std::printf("Accel (m/frame²): truth %.3g, fit %.3g, refined %.3g\n", a_true, a_fit, a_ref);
  EXPECT_LT(a_ref, 0.5 * a_fit);
  const double err = (refined.vertices - truth.vertices).norm(2, {3}).mean().item<double>();
  EXPECT_LT(err, 0.004);
}

// The refinement hands back every joint within its range, even from a start whose fingers
// are bent backwards (the fit's limits off): with bounded joint angles (the default), and
// with axis-angles and w_limits' penalty and clamp; with neither, they stay out.
TEST(Refinement, WithLimitsEveryJointEndsWithinItsRange) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = slab();
  const ObjectDistance distance(object);
  const int N = 6;
  HandMotion start = test::known_motion(models, N, 31);
  for (auto& p : start.hands) {
    p.trans = p.trans + at::tensor({0.0f, 0.0f, 0.3f});
    p.pose.select(1, 4).fill_(-1.2f);  // index PIP about x: far outside
  }
  start.vertices = pose_hand_vertices(models, start);
  const at::Tensor states = at::zeros({N, 7}, at::kFloat);
  const at::Tensor H = test::noisy_keypoints(models, start, 0.0, 0);
  const at::Tensor X = keypoint_features(H, object, states);
  const auto worst = [&](const HandMotion& m) { return test::largest_joint_excess(models, m); };
  EXPECT_GT(worst(start), 20.0);
  RefineOptions bounded, penalty, off;
  bounded.joint_angles = true;
  penalty.w_limits = 1e4;
  EXPECT_LT(worst(refine_hands(models, distance, states, X, start, bounded)), 1e-3);  // float32 poses
  RefineReport report;
  EXPECT_LT(worst(refine_hands(models, distance, states, X, start, penalty, &report)), 1e-3);
  EXPECT_GT(report.hands[0].clamped_joints + report.hands[1].clamped_joints, 0);
  EXPECT_GT(worst(refine_hands(models, distance, states, X, start, off)), 20.0);
}

// Fingers apart (w_separation): a start whose index and middle fingers' bones touch (the
// fit to keypoints that merge them) ends with the two at least the gap apart, even with the
// finger pose held near the start's as the pipelines hold it; without the term they stay.
TEST(Refinement, SeparationPullsMergedFingersApart) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = slab();
  const ObjectDistance distance(object);
  const int N = 6;
  const HandMotion truth = above_the_slab(models, N, 7, 0.3f);
  const at::Tensor states = at::zeros({N, 7}, at::kFloat);
  const at::Tensor H = test::merged_keypoints(models, truth, 0.012);
  ManoFitOptions merged;
  merged.w_separation = 0;  // a start with the fingers merged
  const HandMotion start = fit_mano(models, H, merged);
  const at::Tensor X = keypoint_features(H, object, states);
  RefineOptions off, on;
  off.w_pose = on.w_pose = 1e4;
  on.w_separation = 1e5;
  RefineReport report;
  const double before = test::closest_fingers(models, start);
  const double without = test::closest_fingers(models, refine_hands(models, distance, states, X, start, off));
  const double with = test::closest_fingers(models, refine_hands(models, distance, states, X, start, on, &report));
  std::printf("closest fingers: start %.1f mm, refined without %.1f mm, with %.1f mm\n", before * 1e3, without * 1e3,
              with * 1e3);
  EXPECT_LT(before, kCrossedGap);
  EXPECT_LT(without, kCrossedGap);
  EXPECT_GT(with, kFingerSeparation - 0.001);
  // The term as reported (the left hand's fit merges them; the right's keeps them apart).
  const double b = report.hands[0].before.separation + report.hands[1].before.separation;
  EXPECT_GT(b, 0.0);
  EXPECT_LT(report.hands[0].after.separation + report.hands[1].after.separation, 0.01 * b);
}

TEST(Refinement, RejectsMismatchedInput) {
  const auto& models = test::shipped_hands();
  const ArticulatedObject object = slab();
  const ObjectDistance distance(object);
  const HandMotion m = hands_on_the_slab(models, 3);
  EXPECT_THROW(refine_hands(models, distance, at::zeros({3, 7}), at::zeros({4, 1200}), m), Error);
  EXPECT_THROW(refine_hands(models, distance, at::zeros({2, 7}), at::zeros({3, 1200}), m), Error);
  RefineOptions bad;
  bad.w_pen = -1;
  EXPECT_THROW(refine_hands(models, distance, at::zeros({3, 7}), at::zeros({3, 1200}), m, bad), Error);
}

}  // namespace
}  // namespace bimart
