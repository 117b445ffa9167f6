// A two-part articulated object in its canonical frame (DESIGN §4): the top part rotates
// by the hinge angle about the negative z axis through the origin; the bottom part is fixed
// to the root. Posing: core/object/object_state.h; files: core/object/object_io.h;
// procedural objects: core/object/families/families.h.
#pragma once

#include <string>

#include "core/geometry/triangle_mesh.h"

namespace bimart {

struct ArticulatedObject {
  std::string name;
  TriangleMesh top;     // moving part, canonical frame, metres
  TriangleMesh bottom;  // fixed part, canonical frame, metres

  std::string category;    // family name ("laptop", ...), empty when unknown
  double angle_min = 0.0;  // hinge limits (rad); the closed pose is angle 0
  double angle_max = 3.14159265358979323846;
  // A typical "open" angle (rad), e.g. for pictures. The paper evaluates s_o at an open
  // angle; with the hinge through the origin the angle does not change s_o (DESIGN §4).
  double open_angle = 1.0;
  // Where the geometry came from and its original units, e.g. "box.yaml (mm)"; informative.
  std::string units_note = "m";
};

}  // namespace bimart
