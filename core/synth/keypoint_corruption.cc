#include "core/synth/keypoint_corruption.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <ATen/ATen.h>

#include "core/features/hand_features.h"
#include "core/util/error.h"
#include "core/util/random.h"

namespace bimart {

void KeypointCorruption::validate() const {
  auto check = [](bool ok, const char* what) {
    if (!ok) throw Error(std::string("keypoint corruption: ") + what);
  };
  check(noise >= 0 && jitter >= 0, "noise and jitter must be >= 0");
  check(shift_min >= 0 && shift_max >= shift_min, "need 0 <= shift_min <= shift_max");
  check(stretches_per_second >= 0, "stretches_per_second must be >= 0");
  check(stretch_min >= 1 && stretch_max >= stretch_min, "need 1 <= stretch_min <= stretch_max");
  check(near > 0, "near must be > 0");
}

at::Tensor corrupt_hand_features(const at::Tensor& features, double fps, const KeypointCorruption& o,
                                 std::uint64_t seed, int64_t* shifted_frames) {
  o.validate();
  if (!features.defined() || features.dim() != 2 || features.size(1) != kHandFeatureSize)
    throw Error("keypoint corruption: features must be [N, 1200]");
  if (!(fps > 0)) throw Error("keypoint corruption: fps must be > 0");
  const int64_t N = features.size(0);
  constexpr int J = kHandKeypoints;
  auto [H, D] = split_hand_features(features.to(at::kCPU, at::kDouble).contiguous());
  H = H.contiguous();
  D = D.contiguous();
  double* h = H.data_ptr<double>();  // [2, N, J, 3]
  double* d = D.data_ptr<double>();
  auto at_ = [N](double* base, int hand, int64_t t, int k) { return base + ((hand * N + t) * J + k) * 3; };
  Rng rng(seed);
  const double s_noise = o.noise / std::sqrt(3.0), s_jitter = o.jitter / std::sqrt(3.0);
  int64_t shifted = 0;

  for (int hand = 0; hand < 2; ++hand) {
    // Shifts first, from the true directions.
    std::vector<double> offset(static_cast<size_t>(3 * N), 0.0);
    const double seconds = static_cast<double>(N) / fps;
    int stretches = static_cast<int>(std::floor(o.stretches_per_second * seconds));
    if (rng.chance(o.stretches_per_second * seconds - stretches)) ++stretches;
    for (int s = 0; s < stretches; ++s) {
      const int len = std::min<int64_t>(rng.integer(o.stretch_min, o.stretch_max), N);
      const int64_t start = rng.integer(0, static_cast<int>(N - len));
      const int64_t mid = start + len / 2;
      // Into the object: the mean D of the keypoints nearer than `near`.
      Eigen::Vector3d dir = Eigen::Vector3d::Zero();
      for (int k = 0; k < J; ++k) {
        const Eigen::Map<const Eigen::Vector3d> v(at_(d, hand, mid, k));
        if (v.norm() < o.near) dir += v;
      }
      if (dir.norm() < 1e-9) continue;  // not near the object there
      dir.normalize();
      const double depth = rng.uniform(o.shift_min, o.shift_max);
      const double ramp = std::min(3.0, len / 2.0);
      for (int64_t t = start; t < start + len; ++t) {
        const double e = std::min(static_cast<double>(t - start) + 1, static_cast<double>(start + len - t));
        const double w = e >= ramp ? 1.0 : 0.5 - 0.5 * std::cos(M_PI * e / ramp);
        for (int c = 0; c < 3; ++c) offset[static_cast<size_t>(3 * t + c)] += w * depth * dir[c];
      }
    }
    for (int64_t t = 0; t < N; ++t) {
      bool any = false;
      for (int c = 0; c < 3; ++c) any = any || offset[static_cast<size_t>(3 * t + c)] != 0.0;
      shifted += any;
      const double jx = s_jitter * rng.normal(), jy = s_jitter * rng.normal(), jz = s_jitter * rng.normal();
      for (int k = 0; k < J; ++k) {
        double* p = at_(h, hand, t, k);
        double* q = at_(d, hand, t, k);
        const double jit[3] = {jx, jy, jz};
        for (int c = 0; c < 3; ++c) {
          p[c] += offset[static_cast<size_t>(3 * t + c)] + jit[c] + s_noise * rng.normal();
          q[c] += s_noise * rng.normal();
        }
      }
    }
  }
  if (shifted_frames) *shifted_frames = shifted;
  return join_hand_features(H, D).to(at::kFloat);
}

}  // namespace bimart
