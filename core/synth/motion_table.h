// How synthetic trajectories move each object category (issue: ranges per category are data
// in one table, not code). Directions are in the object's canonical frame (DESIGN §4);
// the world is y-up with a table at y = 0 and the person on the +z side, facing -z.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace bimart {

struct MotionRange {
  double min = 0, max = 0;
};

struct CategoryMotion {
  std::string category;
  Eigen::Vector3d up;       // canonical direction that points up while the object rests
  Eigen::Vector3d front;    // canonical direction from the object towards the person
  MotionRange lift;         // m, how high grabs (and in-air uses) raise the object
  MotionRange carry;        // m, horizontal travel of a grab
  MotionRange turn;         // rad, turn about the vertical (either sign)
  MotionRange tilt;         // rad, tilt while in the air (either sign)
  MotionRange open;         // fraction of the hinge range reached when opening
  MotionRange close;        // ... when closing (min: the usual target; > 0 leaves room for a hand)
  MotionRange grab_angle;   // fraction of the hinge range held during grabs (0 = closed)
  double use_in_air = 0;    // probability that a use sequence is held in the air
  double use_root_motion = 0;  // probability that a use sequence also slides/turns the object
  double hold_open = 0;     // probability that a use sequence starts already open
  // Height (m) of a narrow stand under the object's centre while it rests (0: on the
  // table): flat, thin objects (scissors, a flip phone) are unreachable for a palm grasp
  // when they lie on the table itself.
  double support = 0;
};

// The table, one row per procedural category (core/object/families/families.h).
const std::vector<CategoryMotion>& category_motions();
// The row of `category`; an unknown or empty category gets a generic row (a box-like
// object resting on its bottom part, +y up).
const CategoryMotion& category_motion(const std::string& category);

}  // namespace bimart
