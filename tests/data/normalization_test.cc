#include "core/data/normalization.h"

#include <gtest/gtest.h>

#include <filesystem>

#include <ATen/ATen.h>

#include "core/io/npz.h"
#include "core/util/error.h"
#include "tests/data/tiny_dataset.h"

namespace bimart {
namespace {

using testing_data::tiny_dataset;
using testing_data::tiny_train;
namespace fs = std::filesystem;

std::vector<int64_t> all_windows(const WindowDataset& ds) {
  std::vector<int64_t> v(ds.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = static_cast<int64_t>(i);
  return v;
}

// Per-feature mean and std (float64) of rows [M, F] picked by the mask.
std::pair<at::Tensor, at::Tensor> moments(const at::Tensor& rows) {
  const at::Tensor r = rows.to(at::kDouble);
  return {r.mean(0), r.std(0, /*unbiased=*/false)};
}

const NormalizationStats& train_stats() {
  static const NormalizationStats s = compute_normalization(tiny_train());
  return s;
}

TEST(Normalization, TrainDataIsStandardisedPerFeature) {
  const WindowDataset& ds = tiny_train();
  const NormalizationStats& st = train_stats();
  EXPECT_EQ(st.variant, "np_bps");
  EXPECT_EQ(st.count, 4 * 64 + 64 + 40);  // (window, real frame) pairs of the train split
  ASSERT_EQ(st.x_mean.size(0), 1200);
  ASSERT_EQ(st.obj_mean.size(0), 3079);
  ASSERT_EQ(st.c_mean.size(0), 2048);

  const WindowBatch b = ds.batch(all_windows(ds));
  const at::Tensor valid = b.mask.flatten().nonzero().squeeze(1);
  ASSERT_EQ(valid.numel(), st.count);
  const int64_t m = b.mask.numel();
  struct Case {
    const char* what;
    at::Tensor raw, normalised, std;
  };
  const Case cases[] = {
      {"X", b.hand_features.view({m, 1200}), st.normalize_x(b.hand_features).view({m, 1200}), st.x_std},
      {"[O|G]", object_condition(b.object_features, b.global_states).view({m, 3079}),
       st.normalize_object(b.object_features, b.global_states).view({m, 3079}), st.obj_std},
      {"C", b.contact_maps.view({m, 2048}), st.normalize_c(b.contact_maps).view({m, 2048}), st.c_std},
  };
  for (const Case& c : cases) {
    const auto [raw_mean, raw_std] = moments(c.raw.index_select(0, valid));
    const auto [mean, std] = moments(c.normalised.index_select(0, valid));
    EXPECT_LT((raw_mean - (c.what[0] == 'X'   ? st.x_mean
                           : c.what[0] == 'C' ? st.c_mean
                                              : st.obj_mean))
                  .abs()
                  .max()
                  .item<double>(),
              1e-6)
        << c.what;
    // Features whose std is above the floor come out with std 1; the others (constant on
    // the training data, e.g. the NP-BPS bottom half for one object) with std < 1.
    const at::Tensor varying = c.std > st.std_floor;
    EXPECT_GT(varying.sum().item<int64_t>(), c.raw.size(1) / 3) << c.what;
    EXPECT_LT(mean.abs().max().item<double>(), 1e-4) << c.what;
    EXPECT_LT((std.masked_select(varying) - 1).abs().max().item<double>(), 1e-4) << c.what;
    EXPECT_GE(c.std.min().item<double>(), st.std_floor) << c.what;
    if ((~varying).any().item<bool>())
      EXPECT_LE(std.masked_select(~varying).max().item<double>(), 1.0 + 1e-6) << c.what;
    EXPECT_TRUE(at::allclose(raw_std.clamp_min(st.std_floor), c.std, 1e-5, 1e-9)) << c.what;
  }
  // The NP-BPS bottom half and s_o are constant for one object: their std sits at the floor.
  EXPECT_GT(st.obj_std[3072 + 3].item<double>(), 0.1);  // G's x translation: 0 .. 0.63 m per window
  EXPECT_DOUBLE_EQ(st.obj_std[512 * 3].item<double>(), st.std_floor);
  EXPECT_DOUBLE_EQ(st.obj_std[3078].item<double>(), st.std_floor);  // s_o: one object

  // Round trips.
  const at::Tensor x = b.hand_features.slice(0, 0, 2);
  EXPECT_LT((st.denormalize_x(st.normalize_x(x)) - x).abs().max().item<float>(), 1e-5);
  EXPECT_LT((st.denormalize_c(st.normalize_c(b.contact_maps)) - b.contact_maps).abs().max().item<float>(), 1e-5);
  EXPECT_EQ(st.normalize_x(x.to(at::kDouble)).scalar_type(), at::kDouble);
}

TEST(Normalization, ContactMapsInLogSpace) {
  const WindowDataset& ds = tiny_train();
  const double eps = 0.005;
  const NormalizationStats st = compute_normalization(ds, kNormalizationStdFloor, eps);
  EXPECT_DOUBLE_EQ(st.c_log_eps, eps);
  EXPECT_TRUE(at::equal(st.x_mean, train_stats().x_mean));  // only C changes
  const WindowBatch b = ds.batch(all_windows(ds));
  const at::Tensor valid = b.mask.flatten().nonzero().squeeze(1);
  const int64_t m = b.mask.numel();
  // The statistics are those of log(C + eps); normalised C has mean 0 in that space.
  const at::Tensor logc = at::log(b.contact_maps.view({m, 2048}).to(at::kDouble) + eps).index_select(0, valid);
  const auto [log_mean, log_std] = moments(logc);
  EXPECT_LT((log_mean - st.c_mean).abs().max().item<double>(), 1e-5);
  EXPECT_TRUE(at::allclose(log_std.clamp_min(st.std_floor), st.c_std, 1e-4, 1e-8));
  EXPECT_LT(st.normalize_c(b.contact_maps).view({m, 2048}).index_select(0, valid).to(at::kDouble).mean(0).abs().max()
                .item<double>(),
            1e-4);
  // Round trip, and a 1 mm change at contact moves z far more than the same change at 20 cm.
  EXPECT_LT((st.denormalize_c(st.normalize_c(b.contact_maps)) - b.contact_maps).abs().max().item<float>(), 1e-5);
  at::Tensor c = at::full({1, 2, 1024}, 0.002);
  c[0][1].fill_(0.2);
  const at::Tensor dz = (st.normalize_c(c + 0.001) - st.normalize_c(c)) * st.c_std.view({2, 1024}).to(at::kFloat);
  EXPECT_GT(dz[0][0].mean().item<double>(), 20 * dz[0][1].mean().item<double>());  // log(8/7) / log(206/205) ≈ 27
  // Stored with the statistics, absent (0) for plain ones; negative is refused.
  const fs::path dir = tiny_dataset().dir / "stats_log";
  save_normalization(st, (dir / "stats.npz").string());
  EXPECT_DOUBLE_EQ(load_normalization((dir / "stats.npz").string()).c_log_eps, eps);
  EXPECT_THROW(compute_normalization(ds, kNormalizationStdFloor, -1), Error);
}

TEST(Normalization, ContactBasisIsThePrincipalSubspaceOfTheNormalisedMaps) {
  const WindowDataset& ds = tiny_train();
  const NormalizationStats& st = train_stats();
  const int k = 8;
  const at::Tensor U = contact_basis(ds, st, k);  // [1024, k]
  ASSERT_EQ(U.sizes(), (at::IntArrayRef{1024, k}));
  EXPECT_TRUE(at::allclose(at::mm(U.t(), U), at::eye(k, at::kDouble), 0, 1e-9));  // orthonormal
  // Cross-check with a direct eigen-decomposition of the windows' normalised maps, every
  // (window, real frame, hand) one row: the same subspace (projectors agree).
  const WindowBatch b = ds.batch(all_windows(ds));
  const at::Tensor valid = b.mask.flatten().nonzero().squeeze(1);
  const at::Tensor z = st.normalize_c(b.contact_maps).reshape({-1, 2, 1024}).index_select(0, valid).reshape({-1, 1024});
  const at::Tensor zd = z.to(at::kDouble);
  const at::Tensor V = std::get<1>(at::linalg_eigh(at::mm(zd.t(), zd))).flip({1}).slice(1, 0, k);
  EXPECT_LT((at::mm(U, U.t()) - at::mm(V, V.t())).abs().max().item<double>(), 1e-6);
  // It holds more of the maps' energy than any other k directions, e.g. the first k axes.
  const double kept = at::mm(zd, U).pow(2).sum().item<double>(), axes = zd.slice(1, 0, k).pow(2).sum().item<double>();
  EXPECT_GT(kept, axes);
  EXPECT_GT(kept, 0.5 * zd.pow(2).sum().item<double>());

  // The contact sample: 2k numbers per frame; maps in the subspace come back exactly.
  NormalizationStats pst = st;
  pst.c_basis = U;
  EXPECT_EQ(pst.contact_sample_size(), 2 * k);
  EXPECT_EQ(st.contact_sample_size(), 2048);
  const at::Tensor coeff = at::randn({3, 2, k}, at::kDouble);
  const at::Tensor inside = pst.denormalize_c(at::matmul(coeff, U.t()).to(at::kFloat));  // metres [3, 2, 1024]
  const at::Tensor sample = pst.contact_sample(inside);
  ASSERT_EQ(sample.sizes(), (at::IntArrayRef{3, 2 * k}));
  EXPECT_LT((sample.view({3, 2, k}).to(at::kDouble) - coeff).abs().max().item<double>(), 1e-4);
  EXPECT_LT((pst.contact_from_sample(sample) - inside).abs().max().item<double>(), 1e-5);
  // Without a basis the sample is the 2048 normalised values.
  EXPECT_TRUE(at::allclose(st.contact_sample(b.contact_maps), st.normalize_c(b.contact_maps).flatten(-2)));
  EXPECT_THROW(pst.contact_from_sample(at::zeros({3, 2048})), Error);
  EXPECT_THROW(contact_basis(ds, st, 0), Error);
  EXPECT_THROW(contact_basis(ds, st, 1025), Error);

  // Stored with the statistics; a basis of the wrong shape is refused.
  const fs::path dir = tiny_dataset().dir / "stats_basis";
  save_normalization(pst, (dir / "stats.npz").string());
  EXPECT_TRUE(at::equal(load_normalization((dir / "stats.npz").string()).c_basis, U));
  EXPECT_FALSE(load_normalization((dir / "stats.npz").string()).c_log_eps > 0);
  pst.c_basis = at::zeros({1000, k}, at::kDouble);
  EXPECT_THROW(save_normalization(pst, (dir / "bad.npz").string()), Error);
}

TEST(Normalization, StatisticsComeFromTheTrainSplitOnly) {
  WindowDatasetOptions o;
  o.cache = false;
  const WindowDataset test = WindowDataset::open(tiny_dataset().dir.string(), "test", o);
  const NormalizationStats t = compute_normalization(test);
  EXPECT_EQ(t.count, 64 + 64);  // 80 frames: windows at 0 and 16
  EXPECT_FALSE(at::allclose(t.x_mean, train_stats().x_mean));
}

TEST(Normalization, SaveLoadAndErrors) {
  const fs::path dir = tiny_dataset().dir / "stats";
  const std::string path = (dir / "stats.npz").string();
  save_normalization(train_stats(), path);
  const NormalizationStats back = load_normalization(path);
  EXPECT_EQ(back.variant, "np_bps");
  EXPECT_EQ(back.count, train_stats().count);
  EXPECT_DOUBLE_EQ(back.std_floor, 1e-3);
  EXPECT_EQ(back.c_log_eps, 0.0);
  for (auto [a, b] : {std::pair{&back.x_mean, &train_stats().x_mean},
                      {&back.x_std, &train_stats().x_std},
                      {&back.obj_mean, &train_stats().obj_mean},
                      {&back.obj_std, &train_stats().obj_std},
                      {&back.c_mean, &train_stats().c_mean},
                      {&back.c_std, &train_stats().c_std}})
    EXPECT_TRUE(at::equal(*a, *b));
  const NpzFile f = NpzFile::read(path);
  for (const char* key : {"x_mean", "x_std", "obj_mean", "obj_std", "c_mean", "c_std", "variant", "count"})
    EXPECT_TRUE(f.contains(key)) << key;

  NpzFile bad = f;
  bad.set("c_std", make_npy(std::vector<double>(2047, 1.0)));
  bad.write((dir / "bad.npz").string());
  try {
    load_normalization((dir / "bad.npz").string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("c_std"), std::string::npos) << e.what();
  }
  bad = f;
  bad.set("x_std", make_npy(std::vector<double>(1200, 0.0)));
  bad.write((dir / "bad.npz").string());
  EXPECT_THROW(load_normalization((dir / "bad.npz").string()), Error);
  EXPECT_THROW(train_stats().normalize_x(at::zeros({3, 1199})), Error);
  EXPECT_THROW(train_stats().normalize_c(at::zeros({3, 1024, 2})), Error);
}

}  // namespace
}  // namespace bimart
