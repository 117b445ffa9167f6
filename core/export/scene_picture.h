// Pictures of a sequence for the terminal user (`bimart render`): both hands and the object
// at chosen frames, drawn with core/render from one camera and tiled left to right.
#pragma once

#include <cstdint>
#include <vector>

#include "core/export/scene_source.h"
#include "core/render/rasterizer.h"

namespace bimart {

// The scene's colours (the glTF materials use the same): left hand, right hand, top, bottom.
struct SceneColors {
  Eigen::Vector3d left{0.93, 0.74, 0.62}, right{0.72, 0.50, 0.40};
  Eigen::Vector3d top{0.95, 0.55, 0.20}, bottom{0.30, 0.50, 0.85};
};

// One image per frame (each `size` x `size` pixels), tiled `columns` per row (0: all in one
// row). One camera frames all chosen frames, looking from the person's side (+z) and above.
// Throws bimart::Error naming the frame when it is out of range.
Image render_sequence_frames(const SceneSource& source, const std::vector<std::int64_t>& frames, int size,
                             int columns = 0);

}  // namespace bimart
