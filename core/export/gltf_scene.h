// A sequence as a binary glTF 2.0 scene (.glb; docs/outputs.md): the object's two parts on
// nodes animated by the trajectory, and both hands as skinned meshes on 16-joint MANO-order
// skeletons at the sequence's shape β, rotations animated per frame, pose correctives as
// morph targets with animated weights. Written with tinygltf.
#pragma once

#include <array>
#include <string>

#include "core/hand/hand_model.h"
#include "core/io/sequence.h"
#include "core/object/articulated_object.h"

namespace bimart {

struct GltfOptions {
  // MANO's pose-corrective blend shapes as morph targets: per non-zero posedirs column the
  // motion uses, one target (two when its weight (R_j - I)_e changes sign), scaled so that
  // animated weights stay in [0, 1] (docs/outputs.md). Off: lighter files, LBS only.
  bool correctives = true;
};

// What a scene holds, for reports and tests.
struct GltfSummary {
  std::int64_t frames = 0;
  std::array<int, 2> morph_targets{};  // per hand (up to 2 x 135)
  std::array<int, 2> influences{};     // largest number of joints weighting one vertex, per hand
};

// The scene's joint names in MANO order, e.g. "left_wrist", "left_index1", ...
std::array<std::string, HandModel::kNumJoints> gltf_joint_names(HandSide side);

// The .glb bytes. The sequence must be valid; `models` are {left, right}.
std::string build_glb(const Sequence& sequence, const ArticulatedObject& object,
                      const std::array<const HandModel*, 2>& models, const GltfOptions& options = {},
                      GltfSummary* summary = nullptr);

// build_glb, written atomically to `path` (folders are created). Throws bimart::Error naming
// the path on failure; nothing is left behind then.
GltfSummary write_glb(const Sequence& sequence, const ArticulatedObject& object,
                      const std::array<const HandModel*, 2>& models, const std::string& path,
                      const GltfOptions& options = {});

}  // namespace bimart
