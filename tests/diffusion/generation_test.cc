// Sampling a sequence longer than the model's window with the shipped models: the windows
// are fused at every denoising step, so the frames around a window boundary move like the
// frames elsewhere (issue 15, "Any length"); and the same seed gives the same motion.
#include <gtest/gtest.h>

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>

#include <set>

#include "core/diffusion/generation.h"
#include "stages/guidance.h"
#include "core/util/data_path.h"
#include "tests/diffusion/laptop_trajectory.h"

namespace bimart::diffusion {
namespace {

// A 300-frame trajectory, encoded once for all tests.
const EncodedTrajectory& long_trajectory() {
  static const EncodedTrajectory l = encoded_laptop_use(300);
  return l;
}

at::Tensor generate_motion(int overlap, std::uint64_t seed) {
  const EncodedTrajectory& l = long_trajectory();
  const auto contact = DiffusionModel::load(find_data_file("models/contact.npz"));
  const auto motion = DiffusionModel::load(find_data_file("models/motion.npz"));
  GenerateOptions o;
  o.overlap = overlap;
  const at::Tensor C = contact->generate(l.O, l.G, {}, nullptr, o, at::detail::createCPUGenerator(seed));
  return motion->generate(l.O, l.G, C, nullptr, o, at::detail::createCPUGenerator(seed + 1))[0];  // [N, 1200]
}

struct SeamFigures {
  double accel_seam = 0, accel_elsewhere = 0;  // mean ||x_t - 2 x_{t-1} + x_{t-2}|| per keypoint (m)
  double jump_seam = 0, jump_elsewhere = 0;    // largest mean ||x_t - x_{t-1}|| per keypoint (m)
};

// Frames within 2 of a window's first or last frame are "at a seam".
SeamFigures seam_figures(const at::Tensor& X, int overlap) {
  const std::int64_t N = X.size(0);
  const at::Tensor H = X.slice(1, 0, 600).reshape({N, 200, 3}).to(at::kDouble);
  std::set<std::int64_t> seam;
  for (const auto& [start, length] : DiffusionModel::windows(N, 64, overlap))
    for (const std::int64_t b : {start, start + length - 1})
      if (b > 0 && b < N - 1)
        for (std::int64_t d = -2; d <= 2; ++d) seam.insert(b + d);
  const at::Tensor vel = (H.slice(0, 1) - H.slice(0, 0, -1)).norm(2, -1).mean(-1);                      // frame t = i + 1
  const at::Tensor acc = (H.slice(0, 2) - 2 * H.slice(0, 1, -1) + H.slice(0, 0, -2)).norm(2, -1).mean(-1);  // t = i + 2
  SeamFigures f;
  double n_seam = 0, n_else = 0;
  for (std::int64_t t = 2; t < N; ++t) {
    const double a = acc[t - 2].item<double>();
    const bool at_seam = seam.count(t) > 0;
    (at_seam ? f.accel_seam : f.accel_elsewhere) += a;
    (at_seam ? n_seam : n_else) += 1;
  }
  f.accel_seam /= n_seam;
  f.accel_elsewhere /= n_else;
  for (std::int64_t t = 1; t < N; ++t) {
    const double v = vel[t - 1].item<double>();
    double& m = seam.count(t) ? f.jump_seam : f.jump_elsewhere;
    m = std::max(m, v);
  }
  return f;
}

TEST(Stitching, WindowsCoverTheSequenceWithTheirOverlap) {
  const auto w = DiffusionModel::windows(300, 64, 48);
  ASSERT_EQ(w.front().first, 0);
  ASSERT_EQ(w.back().first + w.back().second, 300);
  for (std::size_t k = 1; k < w.size(); ++k) {
    EXPECT_EQ(w[k].second, 64);
    EXPECT_GE(w[k - 1].first + 64 - w[k].first, 48);  // the last one may overlap more
  }
  EXPECT_EQ(DiffusionModel::windows(40, 64, 48).size(), 1u);
  EXPECT_THROW(DiffusionModel::windows(300, 64, 64), Error);
}

TEST(Stitching, A300FrameSequenceHasNoSeamsBetweenWindows) {
  const at::Tensor X = generate_motion(48, 7);
  ASSERT_EQ(X.size(0), 300);
  ASSERT_TRUE(at::isfinite(X).all().item<bool>());
  const SeamFigures f = seam_figures(X, 48);
  std::printf("fused windows (overlap 48): accel %.3f mm at seams, %.3f mm elsewhere; largest step %.2f / %.2f mm\n",
              f.accel_seam * 1e3, f.accel_elsewhere * 1e3, f.jump_seam * 1e3, f.jump_elsewhere * 1e3);
  EXPECT_LE(f.accel_seam, 1.5 * f.accel_elsewhere);
  // A maximum over few seam frames: the same 1.5x margin (butted windows jump ~17x more).
  EXPECT_LE(f.jump_seam, 1.5 * f.jump_elsewhere);

  // The figures do see seams: windows sampled independently and butted together (overlap
  // 0) jump at every boundary.
  const at::Tensor cut = generate_motion(0, 7);
  const SeamFigures c = seam_figures(cut, 0);
  std::printf("independent windows (overlap 0): accel %.3f mm at seams, %.3f mm elsewhere; largest step %.2f / %.2f mm\n",
              c.accel_seam * 1e3, c.accel_elsewhere * 1e3, c.jump_seam * 1e3, c.jump_elsewhere * 1e3);
  EXPECT_GT(c.accel_seam, 1.5 * c.accel_elsewhere);
}

TEST(Stitching, SameSeedSameMotion) {
  const EncodedTrajectory& l = long_trajectory();
  const auto contact = DiffusionModel::load(find_data_file("models/contact.npz"));
  GenerateOptions o;
  o.overlap = 48;
  o.samples = 2;
  o.sampler.sampler = "ddim";
  o.sampler.steps = 5;
  const at::Tensor a = contact->generate(l.O.slice(0, 0, 120), l.G.slice(0, 0, 120), {}, nullptr, o,
                                         at::detail::createCPUGenerator(3));
  const at::Tensor b = contact->generate(l.O.slice(0, 0, 120), l.G.slice(0, 0, 120), {}, nullptr, o,
                                         at::detail::createCPUGenerator(3));
  ASSERT_EQ(a.sizes(), (std::vector<int64_t>{2, 120, 2, 1024}));
  EXPECT_TRUE(at::equal(a, b));
  EXPECT_FALSE(at::allclose(a[0], a[1]));  // the samples differ
}

// A guidance whose placement puts the hands' keypoints exactly at `target` at the last step.
class PlaceAt : public Guidance {
 public:
  explicit PlaceAt(at::Tensor target) : target_(std::move(target)) {}
  at::Tensor correction(const at::Tensor& x0, std::int64_t, int, int) const override { return at::zeros_like(x0); }
  at::Tensor placement(const at::Tensor& x0, std::int64_t first, int step, int) const override {
    if (step > 0) return {};
    const at::Tensor d = target_.slice(0, first, first + x0.size(1)) - x0.slice(-1, 0, 600);
    return at::cat({d, -d}, -1);
  }

 private:
  at::Tensor target_;  // [N, 600]
};

TEST(Sampling, PlacementIsAppliedAfterClassifierFreeGuidance) {
  const EncodedTrajectory l = encoded_laptop_use(64);
  const auto contact = DiffusionModel::load(find_data_file("models/contact.npz"));
  const auto motion = DiffusionModel::load(find_data_file("models/motion.npz"));
  GenerateOptions o;
  o.sampler.sampler = "ddim";
  o.sampler.steps = 4;
  ASSERT_GT(o.cfg_lambda, 0.0);
  const at::Tensor C = contact->generate(l.O, l.G, {}, nullptr, o, at::detail::createCPUGenerator(5));
  const at::Tensor target = at::full({64, 600}, 0.05f);
  const PlaceAt place(target);
  const at::Tensor X = motion->generate(l.O, l.G, C, &place, o, at::detail::createCPUGenerator(6))[0];
  // The sample ends where the placement put it, not (1 + λ_f) times as far.
  EXPECT_LT((X.slice(-1, 0, 600) - target).abs().max().item<double>(), 1e-4);
}

}  // namespace
}  // namespace bimart::diffusion
