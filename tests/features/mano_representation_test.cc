// MANO-Rep (core/features/mano_representation.h): hands -> representation -> hands gives the
// same posed hands, the representation is in the canonical frame, and 6D rotations decode to
// rotations.
#include "core/features/mano_representation.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "core/hand/hand_model.h"
#include "core/object/object_state.h"
#include "core/refine/mano_fit.h"
#include "core/util/data_path.h"
#include "core/util/error.h"

namespace bimart {
namespace {

struct Hands {
  std::array<HandModel, 2> models;
  std::array<const HandModel*, 2> pointers() const { return {&models[0], &models[1]}; }
};

const Hands& shipped_hands() {
  static const Hands h = [] {
    Hands x;
    x.models = load_hand_models(find_data_file("models/hand/mano_left.npz"), find_data_file("models/hand/mano_right.npz"));
    return x;
  }();
  return h;
}

// Object states that turn, move and open: a non-identity root pose in every frame.
at::Tensor moving_states(int n) {
  at::Tensor s = at::zeros({n, 7}, at::kFloat);
  for (int t = 0; t < n; ++t) {
    s[t][0] = 0.3 + 0.05 * t;
    s[t][1] = 0.4 + 0.1 * t;
    s[t][2] = -0.7;
    s[t][3] = 1.2 - 0.2 * t;
    s[t][4] = 0.2 + 0.03 * t;
    s[t][5] = -0.1;
    s[t][6] = 0.5;
  }
  return s;
}

// Hands in random poses (large global rotations, up to and beyond π) with non-zero shapes.
HandMotion random_hands(int n, std::uint64_t seed) {
  at::manual_seed(static_cast<std::int64_t>(seed));
  HandMotion m;
  for (auto& p : m.hands) {
    p.rot = at::randn({n, 3}) * 1.5;
    p.pose = at::randn({n, 45}) * 0.3;
    p.trans = at::randn({n, 3}) * 0.2 + 0.3;
    p.shape = at::randn({10}) * 1.0;
  }
  return m;
}

double max_diff(const at::Tensor& a, const at::Tensor& b) { return (a - b).abs().max().item<double>(); }

TEST(ManoRepresentation, RoundTripGivesTheSamePosedHands) {
  const auto models = shipped_hands().pointers();
  const int n = 6;
  const HandMotion truth = random_hands(n, 3);
  const at::Tensor states = moving_states(n);
  const at::Tensor rep = mano_representation(models, truth, states);
  ASSERT_EQ(rep.sizes(), (at::IntArrayRef{n, kManoRepSize}));
  const HandMotion back =
      hands_from_mano_representation(models, rep, states, {truth.hands[0].shape, truth.hands[1].shape});
  const at::Tensor v0 = pose_hand_vertices(models, truth), v1 = pose_hand_vertices(models, back);
  EXPECT_LT(max_diff(v0, v1), 1e-4);  // metres
  EXPECT_GT(v0.abs().max().item<double>(), 0.1);  // not trivially zero
  for (int h = 0; h < 2; ++h) EXPECT_TRUE(at::equal(back.hands[h].shape, truth.hands[h].shape));
}

TEST(ManoRepresentation, IsInTheCanonicalFrame) {
  const auto models = shipped_hands().pointers();
  const int n = 4;
  const HandMotion hands = random_hands(n, 5);
  const at::Tensor states = moving_states(n);
  const at::Tensor rep = mano_representation(models, hands, states);
  const PosedHands posed = pose_hands(models, hands);
  for (int t = 0; t < n; ++t) {
    const Eigen::Isometry3d to_world = canonical_to_world(ObjectState::from_row(states[t].contiguous().data_ptr<float>()));
    for (int h = 0; h < 2; ++h) {
      const at::Tensor block = rep[t].narrow(0, h * kManoRepHandSize, kManoRepHandSize);
      for (int j = 0; j < HandModel::kNumJoints; ++j) {
        Eigen::Vector3d c, w;
        for (int k = 0; k < 3; ++k) {
          c[k] = block[kManoRepJoints + 3 * j + k].item<double>();
          w[k] = posed.joints[h][t][j][k].item<double>();
        }
        EXPECT_LT((to_world * c - w).norm(), 1e-5) << "hand " << h << " joint " << j;
        if (j == 0)
          for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(block[kManoRepWrist + k].item<float>(), static_cast<float>(c[k]));
      }
    }
  }
  // The same hands stated in the canonical frame (identity root pose: canonical = world)
  // have the same representation: the object's root pose is removed.
  at::Tensor still = states.clone();
  still.narrow(1, 1, 6).zero_();
  const HandMotion canonical =
      hands_from_mano_representation(models, rep, still, {hands.hands[0].shape, hands.hands[1].shape});
  EXPECT_LT(max_diff(mano_representation(models, canonical, still), rep), 1e-5);
  EXPECT_GT(max_diff(mano_representation(models, hands, still), rep), 1e-2);  // the world hands do not
}

TEST(ManoRepresentation, MeanShapeKeepsTheWristAndTheRotations) {
  // Decoding with β = 0 (the stage's choice) changes the bone lengths, not where the wrist
  // is or how the joints turn: trans is recovered from the wrist, J0(0) rather than J0(β).
  const auto models = shipped_hands().pointers();
  const int n = 3;
  const HandMotion hands = random_hands(n, 7);
  const at::Tensor states = moving_states(n);
  const at::Tensor rep = mano_representation(models, hands, states);
  const HandMotion mean = hands_from_mano_representation(models, rep, states, {at::zeros({10}), at::zeros({10})});
  const PosedHands a = pose_hands(models, hands), b = pose_hands(models, mean);
  EXPECT_LT(max_diff(a.joints.select(2, 0), b.joints.select(2, 0)), 1e-5);
  EXPECT_GT(max_diff(a.joints, b.joints), 1e-4);  // the shapes differ elsewhere
  const at::Tensor again = mano_representation(models, mean, states);
  EXPECT_LT(max_diff(again.narrow(1, 0, kManoRepWrist + 3), rep.narrow(1, 0, kManoRepWrist + 3)), 1e-5);
}

TEST(ManoRepresentation, SixDRotationsAreOrthonormalised) {
  at::manual_seed(2);
  const at::Tensor six = at::randn({50, 6}, at::kDouble);
  const at::Tensor R = rotation_from_6d(six);
  const at::Tensor eye = at::eye(3, at::kDouble).expand({50, 3, 3});
  EXPECT_LT(max_diff(at::matmul(R.transpose(1, 2), R), eye), 1e-12);
  EXPECT_LT(max_diff(at::linalg_det(R), at::ones({50}, at::kDouble)), 1e-12);
  EXPECT_LT(max_diff(rotation_from_6d(rotation_to_6d(R)), R), 1e-12);  // a rotation comes back as itself
  // The first column keeps its direction.
  const at::Tensor a1 = six.narrow(1, 0, 3);
  EXPECT_LT(max_diff(R.select(2, 0), a1 / a1.norm(2, 1, true)), 1e-12);
}

TEST(ManoRepresentation, RefusesBadShapes) {
  const auto models = shipped_hands().pointers();
  EXPECT_THROW(hands_from_mano_representation(models, at::zeros({4, 1200}), moving_states(4),
                                              {at::zeros({10}), at::zeros({10})}),
               Error);
  EXPECT_THROW(mano_representation(models, random_hands(4, 1), moving_states(5)), Error);
}

}  // namespace
}  // namespace bimart
