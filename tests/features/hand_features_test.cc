#include "core/features/hand_features.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "core/hand/hand_model.h"
#include "core/hand/lbs_torch.h"
#include "core/object/families/families.h"
#include "core/object/object_state.h"
#include "core/util/data_path.h"
#include "core/util/error.h"

namespace bimart {
namespace {

struct Scene {
  ArticulatedObject object = make_object("box", 3);
  std::vector<int> keypoints;
  at::Tensor states;    // [N, 7]
  at::Tensor vertices;  // [2, N, V, 3] world
};

// Two procedural hands in random poses near the object, the object moving and opening.
Scene make_scene(int n) {
  Scene s;
  at::manual_seed(11);
  s.states = at::zeros({n, 7}, at::kFloat);
  for (int t = 0; t < n; ++t) {
    s.states[t][0] = 0.2 + 0.1 * t;
    s.states[t][1] = 0.1 * t;
    s.states[t][3] = -0.2;
    s.states[t][4] = 0.05 * t;
    s.states[t][6] = 0.3;
  }
  std::vector<at::Tensor> hands;
  for (const char* file : {"models/hand/mano_left.npz", "models/hand/mano_right.npz"}) {
    const HandModel m = load_hand_model(find_data_file(file));
    s.keypoints = m.keypoints;
    const HandModelTensors mt = HandModelTensors::from(m);
    const LbsTensors posed = lbs(mt, at::randn({n, 3}) * 0.5, at::randn({n, 45}) * 0.2,
                                 at::randn({n, 3}) * 0.1 + 0.1, at::randn({n, 10}) * 0.5);
    hands.push_back(posed.vertices);
  }
  s.vertices = at::stack(hands, 0);
  return s;
}

TEST(HandFeatures, LayoutAndKeypointsInTheCanonicalFrame) {
  const Scene s = make_scene(4);
  const at::Tensor x = hand_features(s.vertices, s.keypoints, s.object, s.states);
  ASSERT_EQ(x.sizes(), (at::IntArrayRef{4, 1200}));
  for (int t = 0; t < 4; ++t) {
    const ObjectState st = ObjectState::from_row(s.states[t].contiguous().data_ptr<float>());
    const Eigen::Isometry3d to_world = canonical_to_world(st);
    const PosedObject posed = pose_canonical(s.object, st.angle);
    for (int h = 0; h < 2; ++h)
      for (int j = 0; j < 100; j += 9) {
        Eigen::Vector3d pw, pc, d;
        for (int c = 0; c < 3; ++c) {
          pw[c] = s.vertices[h][t][s.keypoints[j]][c].item<double>();
          pc[c] = x[t][h * 300 + 3 * j + c].item<double>();
          d[c] = x[t][600 + h * 300 + 3 * j + c].item<double>();
        }
        EXPECT_LT((to_world * pc - pw).norm(), 1e-6);
        // D reaches the nearest vertex of the posed object (brute force over both parts).
        const double best = std::min((posed.top.rowwise() - pc.transpose()).rowwise().norm().minCoeff(),
                                     (posed.bottom.rowwise() - pc.transpose()).rowwise().norm().minCoeff());
        EXPECT_NEAR(d.norm(), best, 1e-6);
        const Eigen::RowVector3d hit = (pc + d).transpose();
        const double on_object = std::min((posed.top.rowwise() - hit).rowwise().norm().minCoeff(),
                                          (posed.bottom.rowwise() - hit).rowwise().norm().minCoeff());
        EXPECT_LT(on_object, 1e-6);
      }
  }
}

TEST(HandFeatures, InverseMappingReturnsWorldKeypoints) {
  const Scene s = make_scene(3);
  const at::Tensor x = hand_features(s.vertices, s.keypoints, s.object, s.states);
  const HandKeypointsWorld w = hand_features_to_world(x, s.states);
  const at::Tensor ids = at::tensor(std::vector<int64_t>(s.keypoints.begin(), s.keypoints.end()));
  const at::Tensor expected = s.vertices.index_select(2, ids);
  ASSERT_EQ(w.positions.sizes(), (at::IntArrayRef{2, 3, 100, 3}));
  EXPECT_LT((w.positions - expected).abs().max().item<float>(), 2e-6);
  // D rotates with the object: |D| is preserved and p + D is an object vertex in the world.
  const auto [h, d] = split_hand_features(x);
  EXPECT_LT((w.directions.norm(2, -1) - d.norm(2, -1)).abs().max().item<float>(), 1e-6);
  EXPECT_TRUE(at::equal(join_hand_features(h, d), x));
}

TEST(HandFeatures, InvariantToTheRootPose) {
  Scene s = make_scene(2);
  const at::Tensor x = hand_features(s.vertices, s.keypoints, s.object, s.states);
  // Move everything by another root pose: same canonical features.
  at::Tensor moved_states = s.states.clone();
  std::vector<at::Tensor> frames;
  for (int t = 0; t < 2; ++t) {
    const ObjectState a = ObjectState::from_row(s.states[t].contiguous().data_ptr<float>());
    ObjectState b = a;
    b.root_rotation = Eigen::Vector3d(0.4, -1.0, 0.2);
    b.root_translation = Eigen::Vector3d(1, 2, 3);
    for (int c = 0; c < 3; ++c) {
      moved_states[t][1 + c] = b.root_rotation[c];
      moved_states[t][4 + c] = b.root_translation[c];
    }
    const Eigen::Isometry3d T = canonical_to_world(b) * canonical_to_world(a).inverse();
    at::Tensor R = at::empty({3, 3}), tr = at::empty({3});
    for (int r = 0; r < 3; ++r) {
      tr[r] = T.translation()[r];
      for (int c = 0; c < 3; ++c) R[r][c] = T.linear()(r, c);
    }
    frames.push_back(at::matmul(s.vertices.select(1, t), R.t()) + tr);
  }
  const at::Tensor y = hand_features(at::stack(frames, 1), s.keypoints, s.object, moved_states);
  EXPECT_LT((x - y).abs().max().item<float>(), 2e-5);
}

TEST(HandFeatures, BadInputsAreClearErrors) {
  const Scene s = make_scene(2);
  EXPECT_THROW(hand_features(s.vertices, {1, 2, 3}, s.object, s.states), Error);
  EXPECT_THROW(hand_features(s.vertices, s.keypoints, s.object, s.states.slice(0, 0, 1)), Error);
  EXPECT_THROW(split_hand_features(at::zeros({2, 1000})), Error);
}

}  // namespace
}  // namespace bimart
