// The check every loaded or imported part passes once closed (core/object/object_io.h has
// the bounds: kMinPartFaces, kMinPartVolumeRatio, kMaxHingeGapRatio).
#pragma once

#include <string>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

// Throws bimart::Error naming `path` and the measured value when a closed canonical part
// has too few faces, no volume, or lies far from the hinge point (the origin).
void check_part_shape(const TriangleMesh& mesh, const std::string& path);

}  // namespace bimart
