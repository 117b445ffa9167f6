// Procedural articulated objects resembling ARCTIC's categories (DESIGN §7). One table holds
// each category's dimension ranges and hinge limits; small builders compose closed
// primitives (core/object/families/primitives.h) into the two parts.
//
// Canonical frame of every family (DESIGN §4): the hinge is the -z axis through the origin
// and opening is a positive angle. Closed (angle 0), an object extends towards -x from the
// hinge, the bottom part below the plane y = 0 and the top part above it, so opening lifts
// the top part towards +y. (The microwave stands on its side in this frame: its height is
// along z and its door is on the face y = 0; scissors lie in the plane z = 0.)
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/object/articulated_object.h"

namespace bimart {

struct DimensionRange {
  std::string name;  // e.g. "width"
  double min = 0;    // metres
  double max = 0;
  std::string what;  // one line for the docs
};

using Dimensions = std::map<std::string, double>;

struct ObjectFamily {
  std::string name;  // the category, e.g. "laptop"
  std::string description;
  std::vector<DimensionRange> dimensions;
  double angle_min = 0, angle_max = 0;  // hinge limits (rad)
  double open_angle = 0;                // a typical open pose (rad)
  double detail = 30;                   // target edge length = largest dimension / detail
  // Builds the parts from sampled dimensions and a target edge length (metres).
  std::function<void(const Dimensions&, double spacing, TriangleMesh& top, TriangleMesh& bottom)> build;
};

// The table, in a fixed order.
const std::vector<ObjectFamily>& object_families();
std::vector<std::string> object_categories();
// Throws bimart::Error with a did-you-mean hint for an unknown category.
const ObjectFamily& object_family(const std::string& category);

// Dimensions drawn uniformly from the family's ranges. Uses std::mt19937_64 (whose output
// the standard fixes) and its own mapping to [0, 1), so results do not depend on the
// standard library's distributions.
Dimensions sample_dimensions(const ObjectFamily& family, std::uint64_t seed);

// A random object of `category`; the same seed gives the same object. name = "<category>_<seed>".
ArticulatedObject make_object(const std::string& category, std::uint64_t seed);
// The object with the given dimensions (missing ones take the middle of their range).
ArticulatedObject make_object(const std::string& category, const Dimensions& dims, const std::string& name);

}  // namespace bimart
