// Fingers side by side (ours, issue 38): along the hand's lateral axis — from the pinky's
// knuckle to the index finger's (MCP joints) — the index finger's PIP joint, DIP joint and
// tip lie beyond the middle finger's, the middle's beyond the ring's and the ring's beyond
// the pinky's, each by at least a gap. It holds in every frame of the synthetic ground
// truth (docs/refinement.md, "Fingers side by side"), and a MANO fit to keypoints whose
// fingers overlap breaks it: fingers crossed or knotted (the "crossed" share of Implaus).
// Unlike a distance between two fingers' bones, the offset keeps its sign when two fingers
// pass each other, so a least-squares solver is told which way to separate them.
#pragma once

#include <array>
#include <cmath>

namespace bimart {

// The least lateral offset of neighbouring fingers in the synthetic ground truth (200
// sequences, 78,076 hand-frames): 17.0 mm at the PIP joints, 7.1 mm at the DIP joints,
// 11.1 mm at the tips, except the index tip, which curls past the middle finger's (down to
// −11.2 mm; 1 % of frames below −0.9) and is left out. The gap is kept under all of them.
constexpr double kFingerGap = 0.005;  // m

// Index, middle, ring, pinky in MANO's joint order (MCP joints 1, 4, 10, 7; PIP and DIP
// follow) and HandModel::fingertips' (thumb, index, middle, ring, pinky) rows 1, 2, 3, 4.
constexpr std::array<int, 4> kOrderedFingerFirstJoint{1, 4, 10, 7};
constexpr std::array<int, 4> kOrderedFingerTip{1, 2, 3, 4};
constexpr int kFingerOrderResiduals = 8;

// gap − (p_a − p_b)·l for the three pairs (index-middle, middle-ring, ring-pinky) × three
// levels (PIP, DIP, tip; not the index-middle tips), positive where the order is broken or the gap short; joints
// [16][3] and tips [5][3] of one hand (either side), any scalar type (Ceres Jets).
template <class T>
void finger_order_shortfall(const T (*joints)[3], const T (*tips)[3], double gap, T* out) {
  T l[3];
  for (int k = 0; k < 3; ++k) l[k] = joints[1][k] - joints[7][k];
  using std::sqrt;
  const T n = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2] + T(1e-18));
  for (int k = 0; k < 3; ++k) l[k] /= n;
  int r = 0;
  for (int pair = 0; pair < 3; ++pair) {
    for (int level = 0; level < (pair == 0 ? 2 : 3); ++level) {
      const T* pa = level < 2 ? joints[kOrderedFingerFirstJoint[pair] + 1 + level] : tips[kOrderedFingerTip[pair]];
      const T* pb =
          level < 2 ? joints[kOrderedFingerFirstJoint[pair + 1] + 1 + level] : tips[kOrderedFingerTip[pair + 1]];
      T d = T(0);
      for (int k = 0; k < 3; ++k) d += (pa[k] - pb[k]) * l[k];
      out[r++] = T(gap) - d;
    }
  }
}

}  // namespace bimart
