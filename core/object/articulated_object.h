// A two-part articulated object in its canonical frame (DESIGN §4): the top part rotates
// by the hinge angle about the negative z axis through the origin; the bottom part is fixed
// to the root. The posing functions and loaders arrive with the objects issue.
#pragma once

#include <string>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

struct ArticulatedObject {
  std::string name;
  TriangleMesh top;     // moving part, canonical frame, metres
  TriangleMesh bottom;  // fixed part, canonical frame, metres
};

}  // namespace bimart
