// Reading and writing articulated objects.
//
// (a) object.yaml beside one mesh file per part (OBJ, PLY, OFF or STL):
//       name: my_box
//       category: box           # optional
//       top: top.obj            # paths relative to the YAML file
//       bottom: bottom.ply
//       units: m                # m | cm | mm (default m); applies to meshes and pivot
//       hinge:                  # optional: only when the meshes are not canonical
//         pivot: [0, 0.1, 0]    # a point on the hinge axis
//         axis: [0, 0, -1]      # direction about which a positive angle opens the top
//       limits: [0.0, 1.9]      # hinge limits (rad), optional
//       open_angle: 1.2         # optional
//     With a hinge given, both parts are moved so that the pivot goes to the origin and the
//     axis to -z (DESIGN §4).
// (b) An ARCTIC template folder: top.obj + bottom.obj in millimetres, already canonical
//     (ARCTIC rotates the top part by the angle about -z through the template's origin).
//
// Every part is checked (core/object/mesh_repair.h), and open parts are closed and oriented
// outwards; what was repaired goes to the log and to the optional report.
#pragma once

#include <string>

#include "core/object/articulated_object.h"
#include "core/object/mesh_repair.h"

namespace bimart {

struct ObjectLoadReport {
  RepairReport top;
  RepairReport bottom;
  std::string str() const;  // "top: ...; bottom: ..."
};

// `path` is an object.yaml, a folder holding one, or an ARCTIC template folder.
ArticulatedObject load_object(const std::string& path, ObjectLoadReport* report = nullptr);
ArticulatedObject load_object_yaml(const std::string& yaml_path, ObjectLoadReport* report = nullptr);
ArticulatedObject load_arctic_object(const std::string& dir, ObjectLoadReport* report = nullptr);

// Writes dir/top.obj, dir/bottom.obj (metres, full precision) and dir/object.yaml, each
// atomically; load_object(dir) reads it back.
void save_object(const ArticulatedObject& object, const std::string& dir);

// Wavefront OBJ with vertices and triangles, 17 significant digits; atomic.
void write_obj(const TriangleMesh& mesh, const std::string& path);

// Metres per unit for "m", "cm", "mm"; throws bimart::Error otherwise.
double metres_per_unit(const std::string& units);

// Parts outside [1 cm, 3 m] of bounding radius (half the box diagonal) are rejected.
constexpr double kMinPartRadius = 0.01;
constexpr double kMaxPartRadius = 3.0;
// A part must be a solid at the hinge (checked after closing its holes): at least 4 faces
// (a tetrahedron), a volume above this share of its radius cubed (zero up to rounding), and
// its nearest point within this many radii (plus 1 cm) of the hinge point.
constexpr int kMinPartFaces = 4;
constexpr double kMinPartVolumeRatio = 1e-6;
constexpr double kMaxHingeGapRatio = 2.0;

}  // namespace bimart
