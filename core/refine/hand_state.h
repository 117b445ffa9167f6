// One hand's per-frame state as the solvers see it: 51 doubles [rot (3), pose (45),
// trans (3)] per frame in one Ceres parameter block, and β (10) per sequence; with the
// conversions to and from bimart::HandMotion (float tensors, ARCTIC layout).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/hand/hand_motion.h"

namespace bimart {

constexpr int kHandStateSize = 51;

// states[h]: N × 51 row-major; betas[h]: 10. Vertices are left undefined.
HandMotion hand_motion_from_states(const std::array<std::vector<double>, 2>& states,
                                   const std::array<std::vector<double>, 2>& betas, int64_t num_frames);
// The inverse, for hand h; throws bimart::Error for missing or mis-shaped fields.
void states_from_hand_motion(const HandMotion& motion, int hand, std::vector<double>* states,
                             std::vector<double>* beta);

}  // namespace bimart
