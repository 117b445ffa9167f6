// Fingers apart (ours, issue 38): the bones of two different fingers — the segments
// MCP–PIP, PIP–DIP, DIP–tip, as the hand-plausibility measure draws them
// (core/metrics/hand_plausibility.h) — keep at least a gap between their axes. Fingers are
// about 1.6 cm thick, so axes closer than that mean skins inside each other; the measure
// flags them under kCrossedGap (8 mm). The MANO fit and the refinement hold the gap as a
// one-sided penalty (`w_separation`): a fit to keypoints that put two fingers into one, or
// a refinement pushing fingers out of an object towards each other, otherwise leaves them
// there (most of the Implaus flags: "index and middle cross"). Unlike the lateral order
// (core/hand/finger_order.h) it also holds fingers that stay in order but close up, and
// the thumb against the fingers.
#pragma once

#include <array>
#include <cmath>

namespace bimart {

constexpr double kFingerSeparation = 0.010;  // m, 2 mm over the measure's kCrossedGap
constexpr int kFingerSeparationResiduals = 90;  // 10 finger pairs × 3 × 3 bones
// Costs carry the term only in frames whose fingers come within the gap plus this (m) at the
// start of a solve: most frames have every pair far apart, and their Jets would cost for
// nothing.
constexpr double kSeparationActive = 0.005;

// The distance between the segments p0–p1 and q0–q1 (closest points as in Ericson, Real-Time
// Collision Detection §5.1.9; written out rather than CGAL's squared_distance so Ceres Jets
// go through it). Segments of nonzero length (bones).
template <class T>
T segment_distance(const T* p0, const T* p1, const T* q0, const T* q1) {
  T d1[3], d2[3], r[3];
  for (int k = 0; k < 3; ++k) {
    d1[k] = p1[k] - p0[k];
    d2[k] = q1[k] - q0[k];
    r[k] = p0[k] - q0[k];
  }
  const auto dot = [](const T* a, const T* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const auto clamp01 = [](T v) { return v < T(0) ? T(0) : (v > T(1) ? T(1) : v); };
  const T a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r), c = dot(d1, r), b = dot(d1, d2);
  const T denom = a * e - b * b;
  T s = denom > T(1e-18) ? clamp01((b * f - c * e) / denom) : T(0);
  T t = (b * s + f) / e;
  if (t < T(0)) {
    t = T(0);
    s = clamp01(-c / a);
  } else if (t > T(1)) {
    t = T(1);
    s = clamp01((b - c) / a);
  }
  T sq = T(1e-18);  // keeps the square root differentiable where the axes meet
  for (int k = 0; k < 3; ++k) {
    const T g = r[k] + d1[k] * s - d2[k] * t;
    sq += g * g;
  }
  using std::sqrt;
  return sqrt(sq);
}

// max(0, gap − distance) for every pair of bones of two different fingers; joints [16][3]
// (MANO order; regressed from the vertices as the measure reads them,
// core/hand/regressed_joints.h) and tips [5][3] (thumb, index, middle, ring, pinky) of one
// hand, any scalar type. out has kFingerSeparationResiduals entries.
template <class T>
void finger_separation_shortfall(const T (*joints)[3], const T (*tips)[3], double gap, T* out) {
  // MANO order: index, middle, pinky, ring, thumb; their first joints and tip rows.
  constexpr std::array<int, 5> first{1, 4, 7, 10, 13};
  constexpr std::array<int, 5> tip{1, 2, 4, 3, 0};
  const auto point = [&](int finger, int i) -> const T* {
    return i < 3 ? joints[first[static_cast<size_t>(finger)] + i] : tips[tip[static_cast<size_t>(finger)]];
  };
  int n = 0;
  for (int f = 0; f < 5; ++f)
    for (int g = f + 1; g < 5; ++g)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          const T d = segment_distance(point(f, a), point(f, a + 1), point(g, b), point(g, b + 1));
          out[n++] = d < T(gap) ? T(gap) - d : T(0);
        }
}

// The distance the closest two bones of two different fingers come (m); joints and tips as above.
inline double closest_fingers(const double (*joints)[3], const double (*tips)[3]) {
  double r[kFingerSeparationResiduals];
  finger_separation_shortfall<double>(joints, tips, 1.0, r);  // gap 1 m: 1 − distance
  double worst = r[0];
  for (double v : r) worst = v > worst ? v : worst;
  return 1.0 - worst;
}

}  // namespace bimart
