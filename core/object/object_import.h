// `bimart object import`: a user's two part meshes and hinge, in any frame and units, turned
// into a canonical object (DESIGN §4; docs/trajectories.md, "Your own object"): a rigid
// transform takes the hinge axis to -z through the origin, then everything is in metres.
// The rest is the canonical pose about the hinge every model sees
// (core/object/canonical_frame.h): turned about the hinge so that the top part lies above the
// bottom part (+y, from the bottom's surface centroid to the top's), and moved along the
// hinge so the object's extent along it is centred on the origin. Holes are filled as on load.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/object/articulated_object.h"
#include "core/object/mesh_repair.h"

namespace bimart {

// A hinge axis in the meshes' frame and units: a point on it and its direction (a positive
// angle turns the top part about it by the right-hand rule).
struct HingeAxis {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
};
// The axis through two points, directed from `a` to `b`.
HingeAxis hinge_through(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

struct ImportOptions {
  std::string top;     // mesh file of the moving part (OBJ, PLY, OFF, STL)
  std::string bottom;  // mesh file of the fixed part
  // Instead of two files: one OBJ whose groups (`g NAME` or `o NAME` lines) label the parts;
  // the faces of group `top_label` move, all others are the fixed part.
  std::string labelled;
  std::string top_label;
  HingeAxis hinge;
  std::string units = "m";  // m | cm | mm: of the meshes and the hinge point
  std::string name = "imported";
  std::string category;                               // optional: a family's default limits
  std::optional<std::pair<double, double>> limits;    // hinge limits (rad)
  std::optional<double> open_angle;                   // rad
};

struct ImportedPart {
  std::string file;
  Eigen::Index vertices_read = 0, faces_read = 0;
  bool closed_as_read = false;
  RepairReport repair;
};

struct ImportReport {
  ImportedPart top, bottom;
  double size = 0;                  // largest side of the box around both parts (m)
  Eigen::Isometry3d to_canonical;   // the meshes' frame, in metres -> canonical frame
  std::vector<std::string> warnings;
  std::string str() const;          // several lines for the terminal (warnings not included)
};

// Throws bimart::Error naming the file or the option at fault: unreadable or bad mesh, a
// zero hinge direction, a part far from the hinge, units, limits.
ArticulatedObject import_object(const ImportOptions& options, ImportReport* report = nullptr);

// The two parts of an OBJ file with groups: faces of the group `top_label` and all others.
// Throws bimart::Error naming the file and the groups it has when the label is missing or
// no face is left for the other part.
std::pair<TriangleMesh, TriangleMesh> split_labelled_obj(const std::string& path, const std::string& top_label);

// Largest side (m) of the axis-aligned box around both parts, closed (angle 0).
double object_size(const ArticulatedObject& object);

// Sizes of the objects the shipped models were trained on: every procedural family over
// seeds 0..9 measures 0.0858 m to 0.5375 m with object_size
// (tests/trajectory/object_import_test.cc re-measures it); an import more than
// kSizeWarningFactor outside this range gets a warning.
constexpr double kTrainingSizeMin = 0.085;
constexpr double kTrainingSizeMax = 0.54;
constexpr double kSizeWarningFactor = 2.0;
// The measured range of object_size over every family and seeds [0, seeds).
std::pair<double, double> procedural_size_range(int seeds);

// `dir` can take a new object: missing, an empty folder, or (with `force`) a folder holding
// an object.yaml. Throws bimart::Error otherwise; call before the work.
void check_object_output(const std::string& dir, bool force);
// save_object into a temporary folder, then renamed to `dir` (replacing it when allowed by
// check_object_output).
void write_object_folder(const ArticulatedObject& object, const std::string& dir, bool force);

}  // namespace bimart
