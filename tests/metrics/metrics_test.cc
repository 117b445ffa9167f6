#include <gtest/gtest.h>

#include <cmath>

#include <ATen/ATen.h>

#include "core/metrics/accel.h"
#include "core/metrics/articulation.h"
#include "core/metrics/contact.h"
#include "core/metrics/hand_vertices.h"
#include "core/metrics/multimodality.h"
#include "core/metrics/penetration.h"
#include "core/metrics/sequence_metrics.h"
#include "core/util/error.h"

namespace bimart {
namespace {

at::Tensor random_vertices(int64_t n, int64_t v, uint64_t seed) {
  at::manual_seed(seed);
  return at::randn({2, n, v, 3}, at::kDouble) * 0.1;
}

TEST(Accel, ConstantAccelerationGivesTheAnalyticValue) {
  // v_t = p + u t + a t² / 2 per vertex: every second difference is a.
  const int64_t n = 20, v = 7;
  const at::Tensor p = random_vertices(1, v, 1);
  const at::Tensor u = random_vertices(1, v, 2);
  const at::Tensor a = at::tensor({0.003, -0.004, 0.0}, at::kDouble);  // |a| = 0.005 m/frame²
  const at::Tensor t = at::arange(n, at::kDouble).reshape({1, n, 1, 1});
  const at::Tensor x = p + u * t + 0.5 * a * t * t;
  EXPECT_NEAR(mean_acceleration(x), 0.005, 1e-12);
  EXPECT_NEAR(mean_acceleration(p + u * t), 0.0, 1e-12);
  EXPECT_TRUE(std::isnan(mean_acceleration(x.slice(1, 0, 2))));
}

TEST(Mul, IdenticalSamplesGiveZeroAndOffsetSamplesTheOffset) {
  const at::Tensor x = random_vertices(9, 11, 3);
  EXPECT_NEAR(multimodality({x, x, x}), 0.0, 1e-15);
  const double d = 0.037;
  const at::Tensor off = at::tensor({2.0, -1.0, 2.0}, at::kDouble) / 3.0 * d;  // |off| = d
  EXPECT_NEAR(multimodality({x, x + off}), d, 1e-12);
  // Three samples at 0, d, 2d along one direction: pairs d, d, 2d.
  EXPECT_NEAR(multimodality({x, x + off, x + 2 * off}), 4 * d / 3, 1e-12);
  EXPECT_THROW(multimodality({x}), Error);
  EXPECT_THROW(multimodality({x, x.slice(1, 0, 3)}), Error);
}

FrameDepths depths_of(std::vector<double> top, std::vector<double> bottom) {
  FrameDepths d;
  d.top = std::move(top);
  d.bottom = std::move(bottom);
  return d;
}

TEST(Penetration, StrictThresholdsAtOneCentimetreAndFiveMillimetres) {
  // Whole-object depth = max(top, bottom). Exactly at a threshold does not count.
  const FrameDepths d = depths_of({0.01, -1, 0.005, -1, 0.0101, -1}, {-1, 0.0099, -1, 0.0051, -1, -0.2});
  const FrameCount c1 = penetration_frames(d, kPenetration1cm);
  const FrameCount c5 = penetration_frames(d, kPenetration5mm);
  EXPECT_EQ(c1.frames, 6);
  EXPECT_EQ(c1.hits, 1);  // only 0.0101
  EXPECT_EQ(c5.hits, 4);  // 0.01, 0.0099, 0.0051, 0.0101; not 0.005 itself
}

at::Tensor states_with(const std::vector<double>& angles, const std::vector<double>& tx) {
  at::Tensor s = at::zeros({static_cast<int64_t>(angles.size()), 7}, at::kFloat);
  for (size_t t = 0; t < angles.size(); ++t) {
    s[t][0] = angles[t];
    s[t][4] = tx[t];
  }
  return s;
}

ArticulatedObject box_object() {
  ArticulatedObject o;
  o.bottom = make_box({-0.2, -0.05, -0.1}, {0, 0, 0.1});
  o.top = make_box({-0.2, 0, -0.1}, {0, 0.02, 0.1});
  return o;
}

TEST(Articulation, CountsOnlyFramesWhereTheAngleChanges) {
  // Angle steps: 0->0 (no), 0->0.1 (yes), 0.1->0.1005 (no: 0.0005), 0.1005->0.2 (yes), last never.
  const at::Tensor s = states_with({0, 0, 0.1, 0.1005, 0.2}, {0, 0, 0, 0, 0});
  const std::vector<bool> ch = angle_changing_frames(s);
  EXPECT_EQ(ch, (std::vector<bool>{false, true, false, true, false}));
  // Touching the top part in frames 0, 1 and 4; frame 3 touches only the bottom part.
  const FrameDepths d = depths_of({0.0, -0.001, -0.1, -0.1, 0.0}, {-0.1, -0.1, -0.1, 0.0, -0.1});
  const FrameCount c = articulation_frames(d, ch);
  EXPECT_EQ(c.frames, 2);
  EXPECT_EQ(c.hits, 1);
}

TEST(Contact, CountsOnlyFramesWhereTheObjectMoves) {
  const ArticulatedObject o = box_object();
  // Moves 0->1 (1 cm), 1->2 no, 2->3 by 5e-6 m (no), 3->4 angle only (the top moves: yes).
  const at::Tensor s = states_with({0, 0, 0, 0, 0.3}, {0, 0.01, 0.01, 0.010005, 0.010005});
  const std::vector<bool> mv = object_moving_frames(o, s);
  EXPECT_EQ(mv, (std::vector<bool>{true, false, false, true, false}));
  const FrameDepths d = depths_of({-0.1, 0.0, 0.0, -0.0049, 0.0}, {-0.1, -0.1, -0.1, -0.1, -0.1});
  const FrameCount c = contact_frames(d, mv);
  EXPECT_EQ(c.frames, 2);
  EXPECT_EQ(c.hits, 1);  // frame 3 (-4.9 mm counts), frame 0 does not
}

TEST(SequenceMetrics, EndToEndOnABoxWithPlacedVertices) {
  const ArticulatedObject o = box_object();
  const ObjectDistance dist(o);
  const int64_t n = 6;
  // The object slides along x by 1 cm per frame and opens in the last steps.
  const at::Tensor s = states_with({0, 0, 0, 0, 0.2, 0.4}, {0, 0.01, 0.02, 0.03, 0.04, 0.05});
  // One vertex per hand; the left one at these depths below the bottom's top face
  // y = 0 (inside the bottom part), the right one far away.
  const std::vector<double> depth = {0.02, 0.007, 0.003, -0.003, -0.01, -0.2};
  at::Tensor v = at::zeros({2, n, 1, 3}, at::kDouble);
  for (int64_t t = 0; t < n; ++t) {
    const double tx = s[t][4].item<double>();
    v[0][t][0][0] = -0.1 + tx;
    v[0][t][0][1] = -depth[static_cast<size_t>(t)];
    v[0][t][0][2] = 0.0;
    v[1][t][0][0] = 5.0;
  }
  SequenceData data;
  data.name = "box";
  data.object_states = s;
  data.hand_vertices = v;
  const SequenceMetrics m = evaluate_sequence(o, dist, data);
  EXPECT_EQ(m.frames, 6);
  EXPECT_EQ(m.pen_1cm.hits, 1);
  EXPECT_EQ(m.pen_1cm.frames, 6);
  EXPECT_EQ(m.pen_5mm.hits, 2);
  // Moving frames 0..4; contact (> -5 mm) in frames 0, 1, 2, 3.
  EXPECT_EQ(m.contact.frames, 5);
  EXPECT_EQ(m.contact.hits, 4);
  // Angle changes in frames 3 and 4. In frame 3 (still closed) the vertex 3 mm above y = 0
  // is inside the top part; in frame 4 the opened top part is 1 cm away.
  EXPECT_EQ(m.articulation.frames, 2);
  EXPECT_EQ(m.articulation.hits, 1);
  EXPECT_TRUE(std::isnan(m.contact_map));
  // Pen 3mm: frames 0 and 1; frames 2 and 3 are 3 mm deep, not more. Depth: the contact
  // frames 0..3 at 20, 7, 3 and 3 mm (frame 3 inside the closed top part).
  EXPECT_EQ(m.pen_3mm.hits, 2);
  EXPECT_EQ(m.contact_depth_frames, 4);
  EXPECT_NEAR(m.contact_depth_sum, 0.033, 1e-9);
  // Solid boxes have no cavity: a vertex inside a part's hull is inside the part.
  EXPECT_EQ(m.cavity.frames, 6);
  EXPECT_EQ(m.cavity.hits, 0);
  const auto table = aggregate_metrics({m, m}, {0.01, 0.03});
  ASSERT_EQ(table.size(), 11u);
  EXPECT_EQ(table[0].name, "Mul");
  EXPECT_NEAR(table[0].value, 2.0, 1e-12);
  EXPECT_EQ(table[2].name, "Pen 1cm");
  EXPECT_EQ(table[2].numerator, 2);
  EXPECT_EQ(table[2].denominator, 12);
  EXPECT_EQ(table[4].name, "Pen 3mm");
  EXPECT_EQ(table[4].numerator, 4);
  EXPECT_EQ(table[5].name, "Depth");
  EXPECT_EQ(table[5].unit, "mm");
  EXPECT_NEAR(table[5].value, 8.25, 1e-6);
  EXPECT_NEAR(table[6].value, 80.0, 1e-12);
  EXPECT_TRUE(std::isnan(table[8].value));
  EXPECT_EQ(table[10].name, "Cavity");
  EXPECT_EQ(table[10].denominator, 12);
  EXPECT_EQ(table[10].value, 0.0);
}

TEST(HandVertices, PosesWithTheShippedModelWhenVerticesAreMissing) {
  HandMotion m;
  const int64_t n = 3;
  for (auto& h : m.hands) {
    h.rot = at::zeros({n, 3});
    h.pose = at::zeros({n, 45});
    h.trans = at::zeros({n, 3});
    h.shape = at::zeros({10});
  }
  m.hands[1].trans[2][0] = 0.25;
  const at::Tensor v = hand_vertices(m);
  ASSERT_EQ(v.dim(), 4);
  EXPECT_EQ(v.size(0), 2);
  EXPECT_EQ(v.size(1), n);
  EXPECT_EQ(v.size(3), 3);
  EXPECT_TRUE(at::isfinite(v).all().item<bool>());
  // Translation moves every vertex of that hand and frame by exactly that much.
  EXPECT_NEAR((v[1][2] - v[1][1]).select(1, 0).mean().item<double>(), 0.25, 1e-6);
  const at::Tensor k = hand_keypoints(m);
  EXPECT_EQ(k.size(2), 100);
  m.vertices = v;
  EXPECT_TRUE(at::equal(hand_vertices(m), v));
}

}  // namespace
}  // namespace bimart
