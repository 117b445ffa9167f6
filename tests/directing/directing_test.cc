// Directing the hands (core/directing/): the `hands:` block read with errors that name the
// file and line; contact rules on known maps; pinned wrists and orientations hit exactly in
// the keypoint space; hands kept off; the kept frames of a redrawn stretch.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <ATen/ATen.h>

#include <filesystem>
#include <fstream>

#include "core/directing/contact_rules.h"
#include "core/directing/hand_constraints.h"
#include "core/directing/hand_pins.h"
#include "core/directing/kept_sample.h"
#include "core/directing/refine_directions.h"
#include "core/features/hand_features.h"
#include "core/geometry/rotation.h"
#include "core/hand/keypoints.h"
#include "core/hand/lbs.h"
#include "core/object/families/families.h"
#include "core/trajectory/trajectory.h"
#include "tests/error_of.h"
#include "tests/synth/shipped_hands.h"

namespace bimart {
namespace {

// A 3 s keyframe-like trajectory: 91 frames at 30 fps starting at t = 0.5 s.
Trajectory trajectory_of(std::int64_t frames = 91) {
  Trajectory t;
  t.states = StateRows::Zero(frames, 7);
  t.fps = 30;
  t.start_time = 0.5;
  return t;
}

std::string write_file(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "bimart_directing_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(HandConstraints, ReadsTheBlockOfATrajectoryFile) {
  const std::string path = write_file("ok.yaml",
                                      "keys: []\n"
                                      "hands:\n"
                                      "  right:\n"
                                      "    - frames: [0, 40]\n"
                                      "      part: top\n"
                                      "      region: {point: [0.1, 0, 0], radius: 0.05}\n"
                                      "  left:\n"
                                      "    - t: [1.5, 2.5]\n"
                                      "      part: none\n"
                                      "      ramp: 4\n"
                                      "    - frame: 70\n"
                                      "      wrist: [0.1, 0.2, 0.3]\n"
                                      "      rotation: {euler_xyz: [0, 90, 0]}\n"
                                      "  both:\n"
                                      "    - frames: [80, 90]\n"
                                      "      part: any\n");
  const HandConstraints c = read_hand_constraints(path, trajectory_of());
  ASSERT_EQ(c.contacts.size(), 4u);
  EXPECT_EQ(c.contacts[0].hand, 1);
  EXPECT_EQ(c.contacts[0].part, ContactPart::Top);
  EXPECT_EQ(c.contacts[0].frames.last, 40);
  ASSERT_TRUE(c.contacts[0].region);
  EXPECT_DOUBLE_EQ(c.contacts[0].region->radius, 0.05);
  // t on the trajectory's clock: (1.5 - 0.5) s * 30 = frame 30 to frame 60.
  EXPECT_EQ(c.contacts[1].hand, 0);
  EXPECT_EQ(c.contacts[1].frames.first, 30);
  EXPECT_EQ(c.contacts[1].frames.last, 60);
  EXPECT_DOUBLE_EQ(c.contacts[1].clearance, 0.03);
  // The clearance fades over the 4-frame ramps: full in the range, raised cosine, then none.
  EXPECT_DOUBLE_EQ(c.contacts[1].clearance_at(45), 0.03);
  EXPECT_NEAR(c.contacts[1].clearance_at(28), 0.03 * 0.5 * (1 + std::cos(M_PI * 2 / 5)), 1e-12);
  EXPECT_EQ(c.contacts[1].clearance_at(25), 0.0);
  EXPECT_EQ(c.contacts[1].clearance_at(65), 0.0);
  EXPECT_EQ(c.contacts[0].clearance_at(10), 0.0);  // not a `none` constraint
  // A ramp is cut to the frames left free by the hand's other contact constraints.
  const std::string cut = write_file("cut.yaml", "keys: []\nhands:\n  right:\n    - frames: [0, 40]\n      part: top\n"
                                                 "    - frames: [44, 60]\n      part: none\n");
  const ContactConstraint& off = read_hand_constraints(cut, trajectory_of()).contacts.at(1);
  EXPECT_EQ(off.ramp_before, 3);
  EXPECT_EQ(off.clearance_at(40), 0.0);
  EXPECT_GT(off.clearance_at(41), 0.0);
  EXPECT_GT(off.clearance_at(68), 0.0);  // after the range: the full 8 frames
  EXPECT_EQ(off.clearance_at(69), 0.0);
  EXPECT_EQ(c.contacts[2].hand + c.contacts[3].hand, 1);  // both: one each
  ASSERT_EQ(c.pins.size(), 1u);
  EXPECT_EQ(c.pins[0].frames.first, 70);
  EXPECT_TRUE(c.pins[0].wrist->isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  const Eigen::Matrix3d R = c.pins[0].rotation->toRotationMatrix();
  EXPECT_NEAR(R(0, 2), 1.0, 1e-12);  // 90 degrees about y: x goes to -z, z to x
  const auto [any, top] = hands_that_may_hold(c, 91);
  EXPECT_FALSE(any[45][0].item<bool>());
  EXPECT_TRUE(any[45][1].item<bool>());
  EXPECT_FALSE(top[45][0].item<bool>());
}

using ::testing::AllOf;
using ::testing::HasSubstr;

// The shipped examples with a `hands:` block read cleanly; each kind of constraint is used
// by one of them; the pose example (a hands file) names the sample it needs until it exists.
TEST(HandConstraints, ShippedExamplesRead) {
  const std::string dir = std::string(BIMART_SOURCE_DIR) + "/examples/trajectories/";
  bool part = false, none = false, region = false, wrist = false, rotation = false;
  for (const char* name : {"laptop_lift_open_directed.yaml", "box_carry_open_left_free.yaml", "box_open_lid_edge.yaml"}) {
    const HandConstraints c = read_hand_constraints(dir + name, read_trajectory(dir + name), true);
    for (const auto& k : c.contacts) {
      (k.part == ContactPart::None ? none : part) = true;
      region = region || k.region.has_value();
    }
    for (const auto& p : c.pins) {
      wrist = wrist || p.wrist.has_value();
      rotation = rotation || p.rotation.has_value();
    }
  }
  EXPECT_TRUE(part && none && region && wrist && rotation);
  const std::string pose = dir + "laptop_right_pose_from_sample.yaml";
  const Trajectory laptop = read_trajectory(dir + "laptop_lift_open.yaml");
  if (!std::filesystem::exists(std::string(BIMART_SOURCE_DIR) + "/out/laptop/sample_0.npz"))
    EXPECT_THAT(test::error_of([&] { read_hand_constraints(pose, laptop, true); }),
                AllOf(HasSubstr("laptop_right_pose_from_sample.yaml:11:"),
                      HasSubstr("pose.sample: no sequence file"), HasSubstr("out/laptop/sample_0.npz")));
}

TEST(HandConstraints, MistakesNameTheFileAndLine) {
  const auto err = [](const std::string& body) {
    const std::string path = write_file("bad.yaml", "keys: []\nhands:\n" + body);
    return test::error_of([&] { read_hand_constraints(path, trajectory_of()); });
  };
  EXPECT_THAT(err("  right:\n    - frames: [0, 10]\n      prat: top\n"),
              AllOf(HasSubstr("bad.yaml:5:"), HasSubstr("unknown key 'prat'"), HasSubstr("did you mean 'part'")));
  EXPECT_THAT(err("  rihgt:\n    - part: top\n"), AllOf(HasSubstr("bad.yaml:3:"), HasSubstr("did you mean 'right'")));
  EXPECT_THAT(err("  right:\n    - frames: [0, 91]\n      part: top\n"),
              AllOf(HasSubstr("bad.yaml:4:"), HasSubstr("[0, 90]")));
  EXPECT_THAT(err("  right:\n    - part: middle\n"), AllOf(HasSubstr("bad.yaml:4:"), HasSubstr("top, bottom, any or none")));
  EXPECT_THAT(err("  left:\n    - frames: [0, 20]\n      part: top\n    - frames: [20, 30]\n      part: none\n"),
              AllOf(HasSubstr("bad.yaml:6:"), HasSubstr("already has a contact constraint over frames 0-20"),
                    HasSubstr("bad.yaml:4:")));
  EXPECT_THAT(err("  left:\n    - part: none\n      region: {point: [0, 0, 0], radius: 0.1}\n"),
              AllOf(HasSubstr("bad.yaml:5:"), HasSubstr("not none")));
  EXPECT_THAT(err("  left:\n    - frame: 3\n      part: top\n      rotation: {euler_xyz: [0, 0, 0]}\n"),
              AllOf(HasSubstr("bad.yaml:"), HasSubstr("rotation goes with wrist")));
  EXPECT_THAT(err("  left:\n    - t: 9\n      part: top\n"), AllOf(HasSubstr("bad.yaml:4:"), HasSubstr("outside the trajectory")));
  EXPECT_THAT(err("  left:\n    - part: top\n      ramp: 4\n"), AllOf(HasSubstr("bad.yaml:5:"), HasSubstr("ramp goes with part: none")));
  EXPECT_THAT(err("  left:\n    - part: none\n      ramp: -1\n"), AllOf(HasSubstr("bad.yaml:5:"), HasSubstr("ramp")));
  EXPECT_THAT(err("  left:\n    - frame: 3\n      pose: {sample: nowhere.npz, frame: 2}\n"),
              AllOf(HasSubstr("bad.yaml:5:"), HasSubstr("no sequence file")));
  // A file given for its constraints must have the block; inline text is read the same way.
  const std::string none = write_file("none.yaml", "keys: []\n");
  EXPECT_THAT(test::error_of([&] { read_hand_constraints(none, trajectory_of(), true); }), HasSubstr("no `hands:` block"));
  EXPECT_EQ(parse_hand_constraints("{right: [{frame: 3, part: bottom}]}", "param", "", trajectory_of()).contacts.at(0).part,
            ContactPart::Bottom);
}

// The refinement holds a hand to the part a constraint asks for over its frames
// (RefineDirections::hold: ObjectPart, -1 none); `none` is a clearance, not a hold.
TEST(RefineDirections, PartsAreHeldOverTheirFrames) {
  const HandConstraints c = parse_hand_constraints(
      "{left: [{frames: [2, 4], part: bottom}], right: [{frames: [1, 2], part: any}, {frames: [7, 8], part: none}]}",
      "param", "", trajectory_of(10));
  const RefineDirections r = refine_directions(c, test::shipped_hands(), at::zeros({10, 7}));
  const int B = static_cast<int>(ObjectPart::Bottom), W = static_cast<int>(ObjectPart::Whole);
  EXPECT_EQ(r.hold[0], (std::vector<int>{-1, -1, B, B, B, -1, -1, -1, -1, -1}));
  EXPECT_EQ(r.hold[1], (std::vector<int>{-1, W, W, -1, -1, -1, -1, -1, -1, -1}));
  ASSERT_EQ(r.clearance[1].size(), 10u);
  EXPECT_GT(r.clearance[1][7], 0.0);
  EXPECT_TRUE(r.clearance[0].empty());
}

// 3 frames; per frame 1024 object points, the first 512 on the top part.
struct RulesCase {
  ArticulatedObject object = make_object("box", 1);
  at::Tensor hits;
  RulesCase() {
    const std::int64_t top = object.top.num_vertices(), bottom = object.bottom.num_vertices();
    at::Tensor row = at::cat({at::arange(512) % top, top + at::arange(512) % bottom});
    hits = row.unsqueeze(0).expand({3, 1024}).contiguous();
  }
};

TEST(ContactRules, PartsNoneAndRegionsOnKnownMaps) {
  RulesCase rc;
  HandConstraints c;
  c.contacts.push_back({1, {0, 1}, ContactPart::Top, std::nullopt, 0.03, {}});
  c.contacts.push_back({0, {1, 2}, ContactPart::None, std::nullopt, 0.04, {}});
  const ContactRules rules(c, rc.object, rc.hits);
  // The right hand touches the bottom part (0 there), 5 cm and more from the top; the
  // left 2 cm from everything.
  at::Tensor C = at::full({2, 3, 2, 1024}, 0.02f);
  C.select(2, 1).slice(-1, 0, 512).copy_(0.05 + 0.1 * at::rand({2, 3, 512}));
  C.select(2, 1).slice(-1, 512, 1024).fill_(0.0f);
  const at::Tensor out = rules.impose(C, 0, 10, 1000);
  for (int t = 0; t < 2; ++t) {
    const at::Tensor right = out.select(1, t).select(1, 1);  // [2, 1024]
    EXPECT_GE(right.slice(-1, 512).min().item<float>(), static_cast<float>(kOtherPartGap) - 1e-7f);
    EXPECT_EQ(std::get<0>(right.slice(-1, 0, 512).min(-1)).max().item<float>(), 0.0f);  // touches the top
    // The top entries shifted down by their minimum: differences between them kept.
    const at::Tensor before = C.select(1, t).select(1, 1).slice(-1, 0, 512);
    EXPECT_TRUE(at::allclose(right.slice(-1, 0, 512), before - std::get<0>(before.min(-1, true)), 0, 1e-6));
  }
  EXPECT_TRUE(at::equal(out.select(1, 2).select(1, 1), C.select(1, 2).select(1, 1)));  // frame 2: free
  EXPECT_TRUE(at::equal(out.select(1, 0).select(1, 0), C.select(1, 0).select(1, 0)));
  EXPECT_NEAR(out.select(1, 1).select(1, 0).min().item<float>(), 0.04f, 1e-7);
  // Flat [B, T, 2048] in, same out; a window further on.
  EXPECT_TRUE(at::equal(rules.impose(C.slice(1, 1, 3).flatten(-2), 1, 0, 1000), out.slice(1, 1, 3).flatten(-2)));

  // A region where the part has no point is refused with its place.
  HandConstraints far;
  far.contacts.push_back({1, {0, 2}, ContactPart::Top, ContactRegion{{5, 5, 5}, 0.01}, 0.03, {"h.yaml", 7, 9}});
  EXPECT_THAT(test::error_of([&] { ContactRules(far, rc.object, rc.hits); }),
              AllOf(HasSubstr("h.yaml:7:9"), HasSubstr("no point of the object's top part")));
}

// Both shipped hands posed with a turn and a translation, as X over N frames (object at
// the origin, so canonical = world), far from an object point cloud at 10 m.
struct PinCase {
  static constexpr int N = 9;
  at::Tensor states = at::zeros({N, 7}, at::kDouble);
  at::Tensor points = at::full({N, 1024, 3}, 10.0f);
  at::Tensor X;
  PinCase() {
    const auto& hands = test::shipped_hands();
    at::Tensor H = at::empty({2, N, kHandKeypoints, 3}, at::kFloat);
    for (int h = 0; h < 2; ++h)
      for (int t = 0; t < N; ++t) {
        const auto r = lbs<double>(*hands[h], Eigen::Vector3d(0.3, -0.2 + 0.02 * t, 0.1), Eigen::VectorXd::Constant(45, 0.1),
                                   Eigen::Vector3d(0.1 * h, 0.2, 0.01 * t), Eigen::VectorXd::Zero(10));
        const std::vector<int> ids = model_keypoints(*hands[h]);
        for (int k = 0; k < kHandKeypoints; ++k)
          for (int c = 0; c < 3; ++c) H[h][t][k][c] = r.vertices(ids[k], c);
      }
    X = join_hand_features(H, at::full_like(H, 0.01f)).unsqueeze(0);  // [1, N, 1200]
  }
  at::Tensor hand(const at::Tensor& x, int t, int h) const {
    return x[0][t].slice(0, 0, 600).view({2, kHandKeypoints, 3})[h];
  }
};

TEST(HandPins, WristAndOrientationArePinnedExactlyAndNeighboursFollow) {
  PinCase pc;
  HandConstraints c;
  HandPin pin;
  pin.hand = 1;
  pin.frames = {4, 4};
  pin.wrist = Eigen::Vector3d(0.05, 0.3, -0.1);
  pin.rotation = Eigen::Quaterniond(axis_angle_to_matrix(Eigen::Vector3d(0, 1.2, 0)));
  c.pins.push_back(pin);
  const HandPins pins(c, test::shipped_hands(), pc.states, pc.points, 1.5);
  // The palm fit reads the pose that posed the hand (the palm is rigid up to pose correctives).
  const auto [w0, R0] = pins.wrist_of(pc.hand(pc.X, 4, 1), 1, 4);
  EXPECT_LT((R0 - axis_angle_to_matrix(Eigen::Vector3d(0.3, -0.2 + 0.08, 0.1))).norm(), 0.02);
  const at::Tensor out = pins.impose(pc.X, 0, 5, 1000);
  const auto [w, R] = pins.wrist_of(pc.hand(out, 4, 1), 1, 4);
  EXPECT_LT((w - *pin.wrist).norm(), 1e-5);
  EXPECT_LT((R - pin.rotation->toRotationMatrix()).norm(), 1e-4);
  // Neighbours move towards the pin, less the farther they are; the left hand stays.
  const auto moved = [&](int t) { return (pc.hand(out, t, 1) - pc.hand(pc.X, t, 1)).norm().item<double>(); };
  EXPECT_GT(moved(3), moved(2));
  EXPECT_GT(moved(2), moved(1));
  EXPECT_LT(moved(0), 0.05 * moved(4));  // exp(-0.5 (4 / 1.5)^2) = 0.028
  EXPECT_TRUE(at::equal(pc.hand(out, 4, 0), pc.hand(pc.X, 4, 0)));
  // H + D, the object point each keypoint refers to, stays.
  const auto sum = [](const at::Tensor& x) { return x.slice(-1, 0, 600) + x.slice(-1, 600, 1200); };
  EXPECT_TRUE(at::allclose(sum(out), sum(pc.X), 0, 1e-5));
  // A window that starts after the pin still pulls its first frame towards it.
  const at::Tensor tail = pins.impose(pc.X.slice(1, 5, 9), 5, 5, 1000);
  const double before = (pins.wrist_of(pc.hand(pc.X, 5, 1), 1, 5).first - *pin.wrist).norm();
  const double after = (pins.wrist_of(tail[0][0].slice(0, 0, 600).view({2, kHandKeypoints, 3})[1], 1, 5).first - *pin.wrist).norm();
  EXPECT_LT(after, 0.8 * before);
}

TEST(HandPins, AHandKeptOffStaysItsClearanceFromTheObjectPoints) {
  PinCase pc;
  // Object points right at the left hand's first keypoint in frames 2..5.
  for (int t = 2; t <= 5; ++t) pc.points[t][0] = pc.hand(pc.X, t, 0)[0] + at::tensor({0.0f, 0.005f, 0.0f});
  HandConstraints c;
  c.contacts.push_back({0, {2, 4}, ContactPart::None, std::nullopt, 0.03, {}, 0});  // no ramp
  const HandPins pins(c, test::shipped_hands(), pc.states, pc.points, 0.0);
  const at::Tensor out = pins.impose(pc.X, 0, 0, 1000);
  for (int t = 2; t <= 4; ++t)
    EXPECT_GE(at::cdist(pc.hand(out, t, 0).unsqueeze(0), pc.points[t].unsqueeze(0)).min().item<float>(), 0.03f);
  EXPECT_TRUE(at::equal(pc.hand(out, 5, 0), pc.hand(pc.X, 5, 0)));  // outside the range
}

// A hand inside the object (a ball of points around its palm, smaller than the hand) is
// moved out of it whole, not further in towards the far side; on the constraint's ramp the
// frames before and after the range are moved by a clearance that fades out.
TEST(HandPins, AHandInsideTheObjectIsMovedOutAndLetsGoSmoothly) {
  PinCase pc;
  at::manual_seed(3);
  for (int t = 0; t < PinCase::N; ++t) {
    const at::Tensor centre = pc.hand(pc.X, t, 1).mean(0) + at::tensor({0.01f, 0.0f, 0.0f});
    const at::Tensor dirs = at::randn({1024, 3}, at::TensorOptions().dtype(at::kFloat));
    pc.points[t] = centre + 0.06f * dirs / dirs.norm(2, 1, true);
  }
  HandConstraints c;
  c.contacts.push_back({1, {4, 5}, ContactPart::None, std::nullopt, 0.03, {}, 2});  // a ramp of 2 frames
  const HandPins pins(c, test::shipped_hands(), pc.states, pc.points, 0.0);
  const at::Tensor out = pins.impose(pc.X, 0, 0, 1000);
  const auto gap = [&](const at::Tensor& x, int t) {
    return at::cdist(pc.hand(x, t, 1).unsqueeze(0), pc.points[t].unsqueeze(0)).min().item<float>();
  };
  for (int t = 4; t <= 5; ++t) {
    EXPECT_LT(gap(pc.X, t), 0.01f);
    EXPECT_GE(gap(out, t), 0.03f) << "frame " << t;
  }
  // The ramp: frames 2-3 and 6-7 moved out part of the way (less than the range), 0-1 and 8 not at all.
  for (int t : {3, 6}) {
    EXPECT_GE(gap(out, t), 0.5f * 0.03f) << "frame " << t;
    EXPECT_LT(gap(out, t), 0.03f) << "frame " << t;
  }
  for (int t : {0, 1, 8}) EXPECT_TRUE(at::equal(pc.hand(out, t, 1), pc.hand(pc.X, t, 1))) << "frame " << t;
}

TEST(KeptSample, WeightsKeepTheOutsideExactlyAndRampAtJoins) {
  KeptSample k;
  k.redraw = {5, 24};
  k.blend = 4;
  const std::vector<double> w = k.weights(40);
  for (int f : {0, 4, 25, 39}) EXPECT_EQ(w[static_cast<std::size_t>(f)], 1.0);
  for (int f = 9; f <= 20; ++f) EXPECT_EQ(w[static_cast<std::size_t>(f)], 0.0);
  for (int f = 5; f < 8; ++f) EXPECT_GT(w[static_cast<std::size_t>(f)], w[static_cast<std::size_t>(f + 1)]);
  EXPECT_NEAR(w[5], w[24], 1e-12);  // symmetric joins
  EXPECT_GT(w[5], 0.5);
  // A stretch at the sequence's start has no join there.
  k.redraw = {0, 9};
  EXPECT_EQ(k.weights(40)[0], 0.0);
  EXPECT_GT(k.weights(40)[9], 0.5);
  // Imposed: the known values exactly where the weight is 1.
  k.redraw = {5, 24};
  const at::Tensor known = at::rand({40, 6}), x = at::rand({2, 40, 6});
  const KeptFrames kept(known, k.weights(40));
  const at::Tensor out = kept.impose(x, 0, 3, 10);
  EXPECT_TRUE(at::equal(out[1].slice(0, 0, 5), known.slice(0, 0, 5)));
  EXPECT_TRUE(at::equal(out[0].slice(0, 9, 21), x[0].slice(0, 9, 21)));
}

}  // namespace
}  // namespace bimart
