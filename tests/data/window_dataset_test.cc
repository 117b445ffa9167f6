#include "core/data/window_dataset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include "core/features/contact_map.h"
#include "core/features/hand_features.h"
#include "core/hand/hand_model.h"
#include "core/metrics/hand_vertices.h"
#include "core/object/canonical_frame.h"
#include "core/object/object_io.h"
#include "core/object/object_state.h"
#include "core/util/data_path.h"
#include "core/util/error.h"
#include "tests/data/tiny_dataset.h"

namespace bimart {
namespace {

using testing_data::tiny_dataset;
using testing_data::tiny_train;
namespace fs = std::filesystem;

// float16 storage: round to nearest, 11 significant bits.
constexpr double kHalfRelative = 1.0 / 2048;       // 2^-11
constexpr double kHalfAbsolute = 1.0 / (1 << 25);  // 2^-25, the subnormal range

// max(|got - exact| - bound(exact)); <= 0 when every entry is within the float16 bound.
double excess_over_half_bound(const at::Tensor& got, const at::Tensor& exact, double extra = 0) {
  const at::Tensor g = got.to(at::kDouble), e = exact.to(at::kDouble);
  return ((g - e).abs() - (e.abs() * kHalfRelative + kHalfAbsolute + extra)).max().item<double>();
}

at::Tensor rounded_to_half(const at::Tensor& t) { return t.to(at::kHalf).to(at::kFloat); }

std::vector<int64_t> all_windows(const WindowDataset& ds) {
  std::vector<int64_t> v(ds.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = static_cast<int64_t>(i);
  return v;
}

int64_t window_index(const WindowDataset& ds, int sequence, int start) {
  for (size_t i = 0; i < ds.size(); ++i)
    if (ds.windows()[i].sequence == sequence && ds.windows()[i].start == start) return static_cast<int64_t>(i);
  ADD_FAILURE() << "no window " << sequence << "@" << start;
  return 0;
}

TEST(WindowDataset, WindowStartsAlignTheLastWindowToTheEnd) {
  EXPECT_EQ(window_starts(100, 64, 16), (std::vector<int32_t>{0, 16, 32, 36}));
  EXPECT_EQ(window_starts(96, 64, 16), (std::vector<int32_t>{0, 16, 32}));
  EXPECT_EQ(window_starts(81, 64, 16), (std::vector<int32_t>{0, 16, 17}));
  EXPECT_EQ(window_starts(64, 64, 16), (std::vector<int32_t>{0}));
  EXPECT_EQ(window_starts(40, 64, 16), (std::vector<int32_t>{0}));
  EXPECT_EQ(window_starts(200, 64, 100), (std::vector<int32_t>{0, 100, 136}));
  EXPECT_THROW(window_starts(10, 64, 0), Error);
}

TEST(WindowDataset, WindowsPaddingAndMask) {
  const WindowDataset& ds = tiny_train();
  ASSERT_EQ(ds.sequences().size(), 3u);
  EXPECT_EQ(ds.num_frames(), 100 + 64 + 40);
  // use_a: 0, 16, 32, 36; grab_b: 0; short_c: 0 (padded).
  ASSERT_EQ(ds.size(), 6u);
  const int32_t expected[6][2] = {{0, 0}, {0, 16}, {0, 32}, {0, 36}, {1, 0}, {2, 0}};
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(ds.windows()[i].sequence, expected[i][0]) << i;
    EXPECT_EQ(ds.windows()[i].start, expected[i][1]) << i;
  }
  const WindowBatch b = ds.batch({5, 3});
  ASSERT_EQ(b.object_features.sizes(), (at::IntArrayRef{2, 64, 1024, 3}));
  ASSERT_EQ(b.global_states.sizes(), (at::IntArrayRef{2, 64, 7}));
  ASSERT_EQ(b.contact_maps.sizes(), (at::IntArrayRef{2, 64, 2, 1024}));
  ASSERT_EQ(b.hand_features.sizes(), (at::IntArrayRef{2, 64, 1200}));
  ASSERT_EQ(b.hit_indices.sizes(), (at::IntArrayRef{2, 64, 1024}));
  ASSERT_EQ(b.mask.sizes(), (at::IntArrayRef{2, 64}));
  EXPECT_EQ(b.object_features.scalar_type(), at::kFloat);
  EXPECT_EQ(b.hit_indices.scalar_type(), at::kLong);
  EXPECT_EQ(b.sequence[0].item<int64_t>(), 2);
  EXPECT_EQ(b.start[1].item<int64_t>(), 36);
  // The short sequence: 40 real frames, then its last frame repeated.
  EXPECT_EQ(b.mask[0].slice(0, 0, 40).sum().item<float>(), 40);
  EXPECT_EQ(b.mask[0].slice(0, 40).sum().item<float>(), 0);
  EXPECT_EQ(b.mask[1].sum().item<float>(), 64);
  for (const at::Tensor* t :
       {&b.object_features, &b.global_states, &b.contact_maps, &b.hand_features, &b.hit_indices, &b.object_states}) {
    const at::Tensor pad = (*t)[0].slice(0, 40);
    EXPECT_TRUE(at::equal(pad, (*t)[0][39].unsqueeze(0).expand_as(pad)));
  }
  EXPECT_FALSE(at::equal(b.object_states[0][38], b.object_states[0][39]));
  EXPECT_FALSE(at::equal(b.hand_features[0][38], b.hand_features[0][39]));
}

TEST(WindowDataset, CompactStorage) {
  const WindowDataset& ds = tiny_train();
  const DatasetSequence& use = ds.sequences()[0];
  const DatasetSequence& grab = ds.sequences()[1];
  EXPECT_EQ(use.object_features.scalar_type(), at::kHalf);
  EXPECT_EQ(use.contact_maps.scalar_type(), at::kHalf);
  EXPECT_EQ(use.hand_features.scalar_type(), at::kHalf);
  EXPECT_EQ(use.hit_template.scalar_type(), at::kShort);  // the box has < 32768 vertices
  EXPECT_EQ(use.object_features.size(0), 100);            // every frame a new hinge angle
  // NP-BPS: the top half (rows 0..511) moves with the hinge, the bottom half never does.
  ASSERT_EQ(use.dynamic_rows.size(0), 512);
  EXPECT_TRUE(at::equal(use.dynamic_rows, at::arange(512, at::kInt)));
  EXPECT_EQ(grab.object_features.size(0), 1);  // hinge fixed: one row ...
  EXPECT_EQ(grab.dynamic_rows.size(0), 0);     // ... and nothing changes
  EXPECT_EQ(grab.feature_row.max().item<int>(), 0);
  // Per frame: states 28 + row 4 + C 4096 + X 2400 bytes; per row and dynamic basis row: O 6
  // + hit 2; per sequence: the templates 1024 x (6 + 2) and the dynamic row list 4 D.
  EXPECT_EQ(use.bytes(), 100u * (28 + 4 + 4096 + 2400) + 100u * 512 * 8 + 1024 * 8 + 512 * 4);
  EXPECT_EQ(grab.bytes(), 64u * (28 + 4 + 4096 + 2400) + 1024 * 8);
  EXPECT_EQ(ds.memory_bytes(), use.bytes() + grab.bytes() + ds.sequences()[2].bytes() + 6 * sizeof(WindowRef));
  // The rebuilt rows are the frames' features.
  const WindowBatch b = ds.batch({0});
  EXPECT_TRUE(at::equal(use.object_rows().slice(0, 0, 64), b.object_features[0]));
  EXPECT_TRUE(at::equal(use.hit_rows().slice(0, 0, 64), b.hit_indices[0]));
}

TEST(WindowDataset, GlobalTranslationIsRelativeToTheWindowsFirstFrame) {
  const WindowDataset& ds = tiny_train();
  const ArticulatedObject object = load_object((tiny_dataset().dir / "objects" / "box").string());
  const float s_o = static_cast<float>(object_scale(object));
  for (int start : {16, 36}) {
    const WindowBatch b = ds.batch({window_index(ds, 0, start)});
    const auto G = b.global_states.accessor<float, 3>();
    const auto S = b.object_states.accessor<float, 3>();
    for (int i = 0; i < 64; ++i) {
      for (int c = 0; c < 3; ++c) {
        const double slope[3] = {0.01, -0.02, 0.005};
        EXPECT_NEAR(G[0][i][3 + c], slope[c] * i, 1e-6) << "start " << start << " frame " << i;
        EXPECT_EQ(G[0][i][c], S[0][i][1 + c]);  // root axis-angle as is
        EXPECT_NEAR(S[0][i][4 + c], testing_data::translation(c, start + i), 1e-6);
      }
      EXPECT_FLOAT_EQ(G[0][i][6], s_o);
    }
  }
}

// The window's features equal the encoders run directly on the same frames.
TEST(WindowDataset, FeaturesEqualTheEncodersOnTheSameFrames) {
  const WindowDataset& ds = tiny_train();
  const int start = 36;
  const WindowBatch b = ds.batch({window_index(ds, 0, start)});
  const Sequence seq = read_sequence((tiny_dataset().dir / "sequences" / "use_a.npz").string());
  // The data set puts every object in its canonical pose about the hinge, states moved with
  // it (core/object/canonical_frame.h); the box family is 1.8° from it.
  const CanonicalObject canonical = to_canonical(load_object((tiny_dataset().dir / "objects" / "box").string()));
  ASSERT_TRUE(canonical.moved);
  const ArticulatedObject& object = canonical.object;
  const at::Tensor states =
      canonical_states(seq.object_states, canonical.from_source).to(at::kFloat).slice(0, start, start + 64);
  const BpsBasis basis = load_bps_basis(find_data_file(default_basis_file(BpsVariant::PerPart)));

  const ObjectEncoding enc = encode_object(object, states, basis, BpsVariant::PerPart);
  EXPECT_TRUE(at::equal(b.object_features[0], rounded_to_half(enc.features)));
  EXPECT_LE(excess_over_half_bound(b.object_features[0], enc.features), 0);
  EXPECT_TRUE(at::equal(b.hit_indices[0], enc.hit_indices));
  EXPECT_TRUE(at::equal(b.global_states[0], enc.global_states));
  EXPECT_TRUE(at::equal(ds.basis_points(), enc.basis_points));

  const at::Tensor hv = hand_vertices(seq.hands).slice(1, start, start + 64);  // [2, 64, V, 3]
  const HandModel model = load_hand_model(find_data_file("models/hand/mano_left.npz"));
  const at::Tensor x = hand_features(hv, model.keypoints, object, states);
  EXPECT_TRUE(at::equal(b.hand_features[0], rounded_to_half(x)));

  // C by another route: hands into the canonical frame, all pairs (8 frames: it is slow).
  const int frames = 8;
  at::Tensor hands = hv.slice(1, 0, frames).to(at::kDouble).clone();
  for (int t = 0; t < frames; ++t) {
    const ObjectState st = ObjectState::from_row(states[t].contiguous().data_ptr<float>());
    const Eigen::Isometry3d w2c = canonical_to_world(st).inverse();
    for (int h = 0; h < 2; ++h) {
      at::Tensor p = hands[h][t];
      auto P = p.accessor<double, 2>();
      for (int64_t v = 0; v < p.size(0); ++v) {
        const Eigen::Vector3d q = w2c * Eigen::Vector3d(P[v][0], P[v][1], P[v][2]);
        for (int c = 0; c < 3; ++c) P[v][c] = q[c];
      }
    }
  }
  const at::Tensor points = basis_hit_points(object, states.slice(0, 0, frames), enc.hit_indices.slice(0, 0, frames));
  const at::Tensor c = contact_maps_exhaustive(points.to(at::kDouble), hands);
  EXPECT_LE(excess_over_half_bound(b.contact_maps[0].slice(0, 0, frames), c, 2e-6), 0);
  EXPECT_GT(c.min().item<double>(), 0);
  EXPECT_LT(c.min().item<double>(), 0.2);  // the hands are near the object
}

TEST(WindowDataset, OtherEncoderVariants) {
  const std::string file = (tiny_dataset().dir / "sequences" / "grab_b.npz").string();
  const Sequence seq = read_sequence(file);
  const CanonicalObject canonical = to_canonical(load_object((tiny_dataset().dir / "objects" / "box").string()));
  const ArticulatedObject& object = canonical.object;
  const at::Tensor states = canonical_states(seq.object_states, canonical.from_source).to(at::kFloat);
  for (BpsVariant v : {BpsVariant::Uniform, BpsVariant::PartAgnostic}) {
    WindowDatasetOptions o;
    o.variant = v;
    o.cache = false;
    const WindowDataset ds = WindowDataset::from_files({file}, o);
    ASSERT_EQ(ds.size(), 1u);
    const BpsBasis basis = load_bps_basis(find_data_file(default_basis_file(v)));
    const ObjectEncoding enc = encode_object(object, states, basis, v);
    const WindowBatch b = ds.batch({0});
    EXPECT_TRUE(at::equal(b.object_features[0], rounded_to_half(enc.features))) << bps_variant_name(v);
    EXPECT_TRUE(at::equal(b.hit_indices[0], enc.hit_indices)) << bps_variant_name(v);
  }
  EXPECT_EQ(parse_bps_variant("npa_bps"), BpsVariant::PartAgnostic);
  try {
    parse_bps_variant("npbps");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("known: np_bps, npa_bps, u_bps"), std::string::npos) << e.what();
  }
}

TEST(WindowDataset, Float16StorageErrorIsBounded) {
  WindowDatasetOptions o;
  o.cache = false;
  o.half_precision = false;
  o.threads = 1;
  const WindowDataset full = WindowDataset::open(tiny_dataset().dir.string(), "train", o);
  EXPECT_EQ(full.sequences()[0].object_template.scalar_type(), at::kFloat);
  const WindowBatch f = full.batch(all_windows(full));
  const WindowBatch h = tiny_train().batch(all_windows(tiny_train()));
  double worst = 0;
  for (auto [got, exact] : {std::pair{&h.object_features, &f.object_features},
                            {&h.contact_maps, &f.contact_maps},
                            {&h.hand_features, &f.hand_features}}) {
    EXPECT_LE(excess_over_half_bound(*got, *exact), 0);
    const at::Tensor e = exact->to(at::kDouble), normal = e.abs() > 1e-4;  // float16's normal range
    worst = std::max(worst, ((got->to(at::kDouble) - e).abs() / e.abs()).masked_select(normal).max().item<double>());
  }
  EXPECT_LE(worst, kHalfRelative);
  EXPECT_GT(worst, 0);  // it is rounded at all
  EXPECT_TRUE(at::equal(h.hit_indices, f.hit_indices));
  EXPECT_TRUE(at::equal(h.global_states, f.global_states));
  EXPECT_TRUE(at::equal(h.mask, f.mask));
  EXPECT_LT(tiny_train().memory_bytes() * 1.8, full.memory_bytes());
}

TEST(WindowDataset, SameSeedSameBatchAndThreadsDoNotMatter) {
  const WindowDataset& ds = tiny_train();
  std::mt19937_64 r1(7), r2(7), r3(8);
  const WindowBatch a = ds.sample_batch(3, r1), b = ds.sample_batch(3, r2), c = ds.sample_batch(3, r3);
  EXPECT_TRUE(at::equal(a.object_features, b.object_features));
  EXPECT_TRUE(at::equal(a.hand_features, b.hand_features));
  EXPECT_TRUE(at::equal(a.contact_maps, b.contact_maps));
  EXPECT_TRUE(at::equal(a.global_states, b.global_states));
  const at::Tensor ka = a.sequence * 1000 + a.start, kc = c.sequence * 1000 + c.start;
  EXPECT_FALSE(at::equal(ka, kc)) << "seeds 7 and 8 drew the same windows";
  EXPECT_EQ(std::get<0>(at::_unique(ka)).numel(), 3);   // distinct when B <= size
  EXPECT_EQ(ds.sample_batch(10, r1).mask.size(0), 10);  // with repetition beyond size
  std::mt19937_64 e1(3), e2(3);
  std::vector<int64_t> order = ds.shuffled(e1);
  EXPECT_EQ(order, ds.shuffled(e2));
  std::sort(order.begin(), order.end());
  EXPECT_EQ(order, all_windows(ds));

  WindowDatasetOptions o;
  o.cache = false;
  o.threads = 1;
  const WindowDataset serial = WindowDataset::open(tiny_dataset().dir.string(), "train", o);
  o.threads = 2;
  const int caller_threads = at::get_num_threads();
  const WindowDataset parallel = WindowDataset::open(tiny_dataset().dir.string(), "train", o);
  EXPECT_EQ(at::get_num_threads(), caller_threads);  // restored after the workers
  const WindowBatch x = serial.batch(all_windows(serial)), y = parallel.batch(all_windows(parallel));
  EXPECT_TRUE(at::equal(x.object_features, y.object_features));
  EXPECT_TRUE(at::equal(x.contact_maps, y.contact_maps));
  EXPECT_TRUE(at::equal(x.hand_features, y.hand_features));
}

TEST(WindowDataset, DiskCacheIsReusedAndRefreshed) {
  const fs::path dir = tiny_dataset().dir;
  fs::remove_all(dir / "cache");
  WindowDatasetOptions o;  // cache on, default folder
  const WindowDataset first = WindowDataset::open(dir.string(), "train", o);
  EXPECT_EQ(first.load_report().computed, 3u);
  EXPECT_EQ(first.load_report().cached, 0u);
  const fs::path cached = dir / "cache" / "np_bps" / "sequences" / "use_a.npz.features";
  ASSERT_TRUE(fs::exists(cached));
  const WindowDataset second = WindowDataset::open(dir.string(), "train", o);
  EXPECT_EQ(second.load_report().cached, 3u);
  const WindowBatch a = first.batch(all_windows(first)), b = second.batch(all_windows(second));
  for (auto [x, y] : {std::pair{&a.object_features, &b.object_features},
                      {&a.contact_maps, &b.contact_maps},
                      {&a.hand_features, &b.hand_features},
                      {&a.hit_indices, &b.hit_indices},
                      {&a.global_states, &b.global_states},
                      {&a.mask, &b.mask}})
    EXPECT_TRUE(at::equal(*x, *y));
  EXPECT_EQ(second.sequences()[1].name, "grab_b");
  EXPECT_EQ(second.sequences()[1].kind, "grab");

  // A newer sequence file and a damaged cache file are recomputed.
  const fs::path grab = dir / "sequences" / "grab_b.npz";
  fs::last_write_time(grab, fs::last_write_time(grab) + std::chrono::seconds(5));
  fs::resize_file(cached, 100);
  const WindowDataset third = WindowDataset::open(dir.string(), "train", o);
  EXPECT_EQ(third.load_report().computed, 2u);
  EXPECT_EQ(third.load_report().cached, 1u);
  EXPECT_TRUE(at::equal(third.batch(all_windows(third)).contact_maps, a.contact_maps));
  // Another variant has its own folder.
  o.variant = BpsVariant::Uniform;
  EXPECT_EQ(WindowDataset::open(dir.string(), "train", o).load_report().computed, 3u);
  EXPECT_TRUE(fs::exists(dir / "cache" / "u_bps" / "sequences" / "short_c.npz.features"));
}

TEST(WindowDataset, ClearErrors) {
  const fs::path dir = tiny_dataset().dir;
  WindowDatasetOptions o;
  o.cache = false;
  try {
    WindowDataset::open(dir.string(), "validation", o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("known: train, test"), std::string::npos) << e.what();
  }
  EXPECT_THROW(tiny_train().batch({6}), Error);
  EXPECT_THROW(tiny_train().batch({}), Error);
  // A sequence whose object is missing: the message names the sequence file.
  Sequence s = testing_data::make_sequence("lost", 10, true, 9);
  s.object = "../objects/nowhere";
  const std::string file = (dir / "broken" / "lost.npz").string();
  write_sequence(s, file);
  try {
    WindowDataset::from_files({file}, o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("lost.npz"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("nowhere"), std::string::npos) << e.what();
  }
  o.stride = 0;
  EXPECT_THROW(WindowDataset::from_files({file}, o), Error);
}

}  // namespace
}  // namespace bimart
