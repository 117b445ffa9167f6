// One benchmark sample for the refinement: a synthesised "use" sequence of a box (the
// synthetic engine, core/synth), its 64 frames from the first grasp on, and its keypoints
// corrupted as a diffusion model errs (core/synth/keypoint_corruption.h).
#pragma once

#include <array>

#include <ATen/ATen.h>

#include "core/features/hand_features.h"
#include "core/hand/hand_model.h"
#include "core/object/families/families.h"
#include "core/object/object_distance.h"
#include "core/refine/mano_fit.h"
#include "core/synth/interaction.h"
#include "core/synth/keypoint_corruption.h"
#include "core/synth/trajectory.h"
#include "core/util/data_path.h"

namespace bimart::bench {

struct RefineSample {
  ArticulatedObject object;
  at::Tensor states;     // [64, 7]
  HandMotion truth;      // with vertices
  at::Tensor keypoints;  // X [64, 1200], corrupted
  std::array<HandModel, 2> hands;
  std::array<const HandModel*, 2> models() const { return {&hands[0], &hands[1]}; }
};

inline const RefineSample& refine_sample() {
  static const RefineSample s = [] {
    RefineSample r;
    r.hands = {load_hand_model(find_data_file("models/hand/mano_left.npz")),
               load_hand_model(find_data_file("models/hand/mano_right.npz"))};
    r.object = make_object("box", 1);
    const ObjectDistance distance(r.object);
    const Trajectory traj = plan_trajectory(r.object, SequenceKind::Use, 2);
    InteractionInfo info;
    const HandMotion full = synthesize_hands(r.object, distance, r.models(), traj, 3, {}, &info);
    const int64_t n = full.num_frames(), T = 64;
    const int64_t start = std::max<int64_t>(0, std::min<int64_t>(std::min(info.grasp_frame[0], info.grasp_frame[1]), n - T));
    r.states = traj.tensor().slice(0, start, start + T).contiguous();
    for (int h = 0; h < 2; ++h) {
      const HandParams& p = full.hands[h];
      r.truth.hands[h] = {p.rot.slice(0, start, start + T), p.pose.slice(0, start, start + T),
                          p.trans.slice(0, start, start + T), p.shape};
    }
    r.truth.vertices = pose_hand_vertices(r.models(), r.truth);
    const at::Tensor X = hand_features(r.truth.vertices, model_keypoints(r.hands[1]), r.object, r.states);
    r.keypoints = corrupt_hand_features(X, traj.fps, {}, 4);
    return r;
  }();
  return s;
}

}  // namespace bimart::bench
