// Band-limiting over time (core/diffusion/temporal_band.h): the projection onto the lowest
// DCT frequencies keeps smooth motion, removes frame-to-frame noise, and sampling with
// GenerateOptions::band returns windows that lie in the band.
#include <gtest/gtest.h>

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>

#include <cmath>

#include "core/diffusion/generation.h"
#include "core/diffusion/temporal_band.h"
#include "core/util/data_path.h"
#include "core/util/error.h"
#include "tests/diffusion/laptop_trajectory.h"

namespace bimart::diffusion {
namespace {

TEST(TemporalBand, IsAnOrthogonalProjectionOfTheRequestedRank) {
  const at::Tensor P = band_projection(64, 8).to(at::kDouble);
  EXPECT_TRUE(at::allclose(P, P.t(), 0, 1e-6));
  EXPECT_TRUE(at::allclose(at::matmul(P, P), P, 0, 1e-5));
  EXPECT_NEAR(P.trace().item<double>(), 8.0, 1e-4);
  EXPECT_TRUE(at::equal(band_projection(10, 10), at::eye(10, at::kFloat)));
  EXPECT_THROW(band_projection(0, 3), Error);
  EXPECT_THROW(band_projection(8, 0), Error);
}

TEST(TemporalBand, KeepsLowFrequenciesAndRemovesHighOnes) {
  const std::int64_t n = 64;
  const at::Tensor t = at::arange(n, at::kDouble);
  const auto cosine = [&](int k) { return (M_PI / n * (t + 0.5) * k).cos(); };
  const at::Tensor low = (0.3 + cosine(1) - 0.5 * cosine(7)).unsqueeze(1);  // [64, 1]
  const at::Tensor high = cosine(11).unsqueeze(1);
  EXPECT_LT((band_limit(low, 8) - low).abs().max().item<double>(), 1e-5);
  EXPECT_LT(band_limit(high, 8).abs().max().item<double>(), 1e-5);
  EXPECT_LT((band_limit(low + high, 8) - low).abs().max().item<double>(), 1e-5);

  // A minimum-jerk reach of 20 cm over the window (how the synthetic hands move) loses under 0.2 mm in
  // band 8, while white noise of 1 mm per frame keeps only ~sqrt(8/64) of its size.
  const at::Tensor s = t / (n - 1);
  const at::Tensor reach = (0.2 * (10 * s.pow(3) - 15 * s.pow(4) + 6 * s.pow(5))).unsqueeze(1);
  EXPECT_LT((band_limit(reach, 8) - reach).abs().max().item<double>(), 2e-4);
  const at::Tensor noise = 1e-3 * at::randn({n, 200}, at::detail::createCPUGenerator(5)).to(at::kDouble);
  const double kept = band_limit(noise, 8).norm().item<double>() / noise.norm().item<double>();
  EXPECT_NEAR(kept, std::sqrt(8.0 / 64.0), 0.05);

  // Batched [B, frames, D] and off (keep 0 or >= frames) returns the input.
  const at::Tensor batch = at::stack({low + high, high}, 0);
  EXPECT_TRUE(at::allclose(band_limit(batch, 8)[0], low, 0, 1e-5));
  EXPECT_TRUE(band_limit(batch, 0).is_same(batch));
  EXPECT_TRUE(band_limit(batch, 64).is_same(batch));
  // A projection built once gives the same, and must fit the frames.
  EXPECT_TRUE(at::allclose(band_limit(batch, band_projection(64, 8)), band_limit(batch, 8), 0, 1e-6));
  EXPECT_TRUE(band_limit(batch, at::Tensor()).is_same(batch));
  EXPECT_THROW(band_limit(batch, band_projection(32, 8)), Error);
}

TEST(TemporalBand, SampledWindowsLieInTheBand) {
  const EncodedTrajectory e = encoded_laptop_use(64);
  const auto contact = DiffusionModel::load(find_data_file("models/contact.npz"));
  GenerateOptions o;
  o.sampler.sampler = "ddim";
  o.sampler.steps = 5;
  o.band = 8;
  const at::Tensor C = contact->generate(e.O, e.G, {}, nullptr, o, at::detail::createCPUGenerator(3));
  ASSERT_EQ(C.sizes(), (std::vector<int64_t>{1, 64, 2, 1024}));
  // In the band up to the clamp at 0 m of the denormalised maps: project the unclamped
  // part only.
  const at::Tensor flat = C[0].flatten(1).to(at::kDouble);
  const at::Tensor positive = (flat > 1e-4).all(0);  // points never clamped
  const at::Tensor kept = flat.index({at::indexing::Slice(), positive});
  ASSERT_GT(kept.size(1), 100);
  EXPECT_LT((band_limit(kept, 8) - kept).abs().max().item<double>(), 1e-4);
  o.band = 0;
  const at::Tensor free = contact->generate(e.O, e.G, {}, nullptr, o, at::detail::createCPUGenerator(3));
  const at::Tensor f = free[0].flatten(1).to(at::kDouble).index({at::indexing::Slice(), positive});
  EXPECT_GT((band_limit(f, 8) - f).abs().max().item<double>(), 1e-3);  // without it, it is not
}

}  // namespace
}  // namespace bimart::diffusion
