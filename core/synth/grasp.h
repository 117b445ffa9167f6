// Grasp planning on one part of an articulated object (DESIGN §7): place the palm against the
// surface at a contact site, at a sampled wrist angle, then close each finger until it
// touches, within the synergy's joint range, with no vertex deeper than a limit. Everything
// happens in the part's own frame (the top part at angle 0, the bottom in the canonical
// frame), so a grasp stays valid while the part moves.
#pragma once

#include <array>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/geometry/triangle_mesh.h"
#include "core/hand/hand_model.h"
#include "core/object/articulated_object.h"
#include "core/object/object_distance.h"
#include "core/util/random.h"

namespace bimart {

// A hand of one shape in its local frame (global rotation and translation zero).
struct HandGeometry {
  const HandModel* model = nullptr;
  Eigen::VectorXd betas;           // 10
  Eigen::Vector3d wrist;           // root joint J0 (the centre of the global rotation)
  Eigen::Vector3d palm_point;      // centre of the palm's surface
  Eigen::Vector3d palm_normal;     // unit, the way the palm faces
  Eigen::Vector3d finger_dir;      // unit, the way the straight fingers point
  // Vertex ids per digit in MANO order (index, middle, pinky, ring, thumb), by their
  // strongest skinning joint; palm = the wrist joint's.
  std::array<std::vector<int>, 5> digits;
  std::vector<int> palm;
};
HandGeometry hand_geometry(const HandModel& model, const Eigen::VectorXd& betas);

// Finger pose (45, flat) from per-digit curls (MANO digit order; 0 straight, 1 a loose fist)
// and a spread of the fingers (rad, + fans them out), mirrored for the left hand.
Eigen::VectorXd grasp_finger_pose(const HandGeometry& hand, const std::array<double, 5>& curl, double spread);

// Hand vertices in its local frame for a finger pose.
Points3 local_hand_vertices(const HandGeometry& hand, const Eigen::VectorXd& finger_pose);

struct Grasp {
  ObjectPart part = ObjectPart::Bottom;  // Top or Bottom
  Eigen::Isometry3d part_from_hand = Eigen::Isometry3d::Identity();
  Eigen::VectorXd finger_pose;           // 45, flat
  std::array<double, 5> curl{};
  std::array<double, 5> start_curl{};  // where closing began: curls between it and `curl` are clear
  double spread = 0;
  Eigen::Vector3d site = Eigen::Vector3d::Zero();    // contact site, part frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY(); // outward normal there, part frame
  double depth = 0;   // deepest hand vertex (m, > 0 inside) against both parts at `angle`
  int contacts = 0;   // hand vertices within 5 mm of the surface
};

struct GraspRequest {
  ObjectPart part = ObjectPart::Bottom;
  double angle = 0;  // hinge angle at which the grasp is taken
  // World pose of the part when the grasp is taken (to judge sites and wrist angles).
  Eigen::Isometry3d world_from_part = Eigen::Isometry3d::Identity();
  // Optional filters: a contact site (part frame position and outward normal), and the
  // hand's rotation in the world.
  std::function<bool(const Eigen::Vector3d& site, const Eigen::Vector3d& normal)> accept_site;
  std::function<bool(const Eigen::Matrix3d& world_rotation, const Eigen::Vector3d& world_site)> accept_wrist;
  // The table: the hand stays above this world height (m); -infinity for none.
  double table_height = -std::numeric_limits<double>::infinity();
  // Hinge angles the grasp must also be clear of the other part at (the angles it passes
  // through while held); the grasp angle itself is always checked.
  std::vector<double> hold_angles;
  // The hinge angle when the hand lets go (NaN: the grasp angle): the digits open there, so
  // their whole closing path must be clear of the other part at that angle too.
  double release_angle = std::numeric_limits<double>::quiet_NaN();
  // Optional last check of a finished grasp: its hand vertices in the part's frame.
  std::function<bool(const Points3& vertices)> accept_hand;
  double max_depth = 0.002;  // no vertex deeper than this (m)
  int candidates = 4;        // valid grasps compared; the best by contact wins, with jitter
  int max_tries = 40;        // sites tried before giving up
};

// The part's mesh in its own frame with outward vertex normals (built once per object).
struct PartSurface {
  ObjectPart part = ObjectPart::Bottom;
  const TriangleMesh* mesh = nullptr;
  Eigen::MatrixX3d normals;
};

class GraspPlanner {
 public:
  GraspPlanner(const ArticulatedObject& object, const ObjectDistance& distance);

  // nullopt when no valid grasp was found within the request's tries.
  std::optional<Grasp> plan(const HandGeometry& hand, const GraspRequest& request, Rng& rng) const;

  // Deepest of `points` (given in the frame of `part`) against both parts at hinge `angle`.
  double depth(ObjectPart part, double angle, const Points3& points) const;
  // depth(part, angle, points) > threshold (>= 0), cheaper (MeshDistance::any_deeper_than).
  bool deeper_than(ObjectPart part, double angle, const Points3& points, double threshold) const;
  // The same against the other part only.
  double depth_other(ObjectPart part, double angle, const Points3& points) const;

  const PartSurface& surface(ObjectPart part) const { return part == ObjectPart::Top ? top_ : bottom_; }
  const ArticulatedObject& object() const { return object_; }

 private:
  // Why candidates fail, counted for the debug log.
  enum class Reject { Site, Normal, Wrist, Obstructed, HeldOff, Digit, Final, Hinge, OtherHand, Count };
  using RejectCounts = std::array<int, static_cast<size_t>(Reject::Count)>;
  std::optional<Grasp> try_site(const HandGeometry& hand, const GraspRequest& request, int vertex,
                                double wrist_angle, Rng& rng, RejectCounts& counts) const;
  const MeshDistance& other_part(ObjectPart part) const;
  // `points` given in the frame of `part`, moved into the other part's frame at `angle`.
  Points3 in_other_frame(ObjectPart part, double angle, const Points3& points) const;
  const ArticulatedObject& object_;
  const ObjectDistance& distance_;
  PartSurface top_, bottom_;
};

}  // namespace bimart
