// Refining fitted hands against the object (paper §3.4 eq. 9–12, DESIGN §5), by Ceres over
// all frames of each hand, starting from a MANO fit (core/refine/mano_fit.h).
//
// Cost per hand (means over N frames and J = 100 keypoints or A acceleration vertices, so
// weights do not depend on counts; penetration sums the inside vertices like the paper):
//   w_proj · mean_{t,k} dist(K_tk + D̂_tk, surface)²    keypoint + predicted direction on the surface
//   w_pen  · Σ_{t, v inside} depth_tv² / (N·J)           hand vertices inside the object
//   w_acc  · mean_{t,a} ||v_ta − 2 v_t−1,a + v_t−2,a||²  second differences of hand vertices
//   w_fit  · mean_{t,k} ||K_tk − Ĥ_tk||²                 keypoints near the prediction (ours)
//   w_hold · Σ_{t held} max(0, −sd(K_t*))² / N           a hand on the object where it must be (ours)
//   w_limits · Σ_{t,j} ||0.03 m · excess_tj||² / N       anatomical joint limits (ours; core/hand/joint_limits.h),
//                                                         with every joint clamped into its range after each round
//   w_pose · Σ_t ||0.03 m · (θ_t − θ_fit,t)||² / N       finger pose near the fit's (ours)
//   w_separation · Σ_t Σ_pairs max(0, gap − d)² / N      two fingers' bones apart (ours; core/hand/finger_separation.h)
// The paper sums unsquared distances and takes 100 gradient steps; a least-squares solver
// converges, so it squares them and adds the fit term to hold what the other terms leave
// free (a contact constrains a keypoint along the surface normal only). Its weights
// w_proj = 100, w_pen = 10, w_acc = 1000 are the defaults; w_fit = 30 makes the
// acceleration term a smoothing of ratio w_acc / w_fit ≈ 33 (frame-to-frame jitter is
// damped about 500-fold; a movement over 10 frames loses about a quarter of its
// amplitude, one over 20 frames about 2 %)
// and lets a contact outweigh a keypoint threefold. Penetration is held under a
// tolerance by growing the penetration weight of the frames that stay too deep (below).
//
// The object surface enters linearised: every outer iteration queries, per part in the
// part's frame (CGAL AABB tree and inside test, core/object/object_distance.h), the
// nearest surface point and normal of each projected keypoint and of each hand vertex
// inside or near the object, and the inner Ceres solve works with those tangent planes.
// The acceleration term uses `accel_vertices` vertices spread over the hand parts (the
// mean over them estimates the mean over all vertices); β stays at the fit's value.
// Per evaluation, each frame's vertices and Jacobians are posed once (Jets through
// lbs_subset) and shared by all terms that read that frame.
//
// Hold (ours, off by default): an object moves only while a hand holds it, and its top
// part turns only while a hand is on it. In such frames (HeldFrames) the starting hand
// nearer the object (its top part) is held to it: its keypoint nearest the object (the top
// part), re-chosen every round, is pulled onto the surface from outside.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <ATen/core/Tensor.h>

#include "core/hand/hand_model.h"
#include "core/hand/hand_motion.h"
#include "core/metrics/held_frames.h"
#include "core/object/articulated_object.h"
#include "core/object/object_distance.h"

namespace bimart {

struct RefineOptions {
  double w_proj = 100, w_pen = 10, w_acc = 1000;  // DESIGN §5
  double w_fit = 30;
  int outer_iterations = 3;    // re-linearisations of the object surface
  // Penetration is a constraint in effect: after every outer iteration, each frame whose
  // deepest vertex is deeper than pen_tolerance has its penetration weight multiplied by
  // pen_growth, and rounds go on past outer_iterations while one is, up to
  // max_outer_iterations. (A few deep vertices weigh little beside the keypoints and the
  // acceleration of a whole hand; growing the weight where needed moves them without
  // stiffening the rest.)
  double pen_tolerance = 0.002;  // m
  double pen_growth = 10;
  // The largest multiplier a frame's penetration weight grows to (ours; the paper has no
  // growth). Past ~1e4 it outweighs the acceleration term so far that a frame stuck in a
  // thin wall (a 5 mm lid holds a vertex 2.5 mm deep, over pen_tolerance, whatever the
  // weight) jumps from its neighbours: hands on a hollow box moved at Accel 0.33 after 6
  // rounds (boost 1e6), 0.09 after 4 (1e3).
  double max_pen_boost = 1e300;
  int max_outer_iterations = 4;
  int max_iterations = 4;      // Levenberg–Marquardt steps per outer iteration
  double pen_margin = 0.005;   // m: vertices closer than this to the surface get a plane
  // m: in a frame whose deepest vertex is deeper than this, inside vertices whose nearest
  // surface faces away from the rest of the hand take the plane where they leave the object
  // towards it (a thin part passed through; 0 = always, 1e9 = never: nearest surface)
  double pen_exit_depth = 0.005;
  // frames: every frame within this many frames of a deep one (with a vertex inside) leaves
  // the way the deep frames there leave on average (0 = each deep frame its own way, the
  // others by their nearest planes)
  int pen_exit_smooth = 0;
  // Hollow parts (ours; false: the paper's, the library default): hand vertices in a part's
  // cavity (ObjectDistance::cavity_points, more than kCavityFloor in) whose way to the rest
  // of the hand crosses a wall count as that far inside it, and leave through it
  // (core/refine/exit_plane.h, exit_plane_through); in a frame found so once, the inside
  // vertices leave the same way in later rounds, however shallow (a 5 mm wall holds a
  // finger at most 2.5 mm deep: never deep enough for pen_exit_depth).
  bool pen_cavities = false;
  // Fingers through a thin part (ours; false: the paper's, the library default): in a frame
  // that leaves the object one way (pen_exit_depth), an outside vertex whose nearest face
  // faces away from that way, of a finger (or the palm) with a vertex inside, takes the
  // plane where a ray from it along the way passes through the part (exit_plane_through),
  // within kThroughReach. Without it a finger through a notebook's cover is locked there:
  // its inside vertices are pushed up, its tip below is held below by the bottom face, and
  // the finger settles across the cover's middle plane (6.4 mm deep in a 12.8 mm cover).
  bool pen_fingers_through = false;
  int accel_vertices = 48;     // vertices per hand in the acceleration term
  int threads = 0;             // 0: all cores (the hands run in parallel)
  double w_hold = 0;           // the hold term (ours; 0 = off, the paper's)
  // Joint limits (ours, off by default): a joint 1° beyond its range costs about as much as
  // a frame whose every keypoint is 1 cm off its prediction (w_fit), and after every round
  // each joint still outside is clamped to its range (JointLimits::clamp); 0 = neither (the
  // paper's). Measured (docs/refinement.md): with 1e4, hands stay anatomical but keep out
  // of the object less well — Levenberg–Marquardt stalls on the penalty's edge — so the
  // default waits for joint angles as bounded parameters.
  double w_limits = 0;
  // Finger pose held near the start's (ours; 0 = the paper's, the library default):
  // w_pose · Σ_t ||0.03 m · (θ_t − θ_start,t)||² / N over the finger parameters, so
  // penetration is resolved by moving the hand rather than by curling its fingers (the
  // start, the MANO fit, has anatomical fingers). Measured (docs/refinement.md): free, the
  // refinement curled fingers into fists (Implaus 98 %); with 1e4, 10 %, and Pen 5mm
  // 38 → 31 %. pipelines/bimart.yaml sets 1e4.
  double w_pose = 0;
  // Fingers apart (ours; 0 = the paper's, the library default): w_separation ·
  // Σ_t Σ max(0, gap − distance)² / N over the bone pairs of two different fingers
  // (core/hand/finger_separation.h), so fingers pushed out of the object do not end inside
  // each other.
  double w_separation = 0;
  double separation_gap = 0.010;  // m (kFingerSeparation)
  // The hand's other constraints grow with penetration (ours; 0: fixed, the paper's, the
  // library default): a frame's separation and joint-limit residuals are scaled by its
  // penetration boost to this power (1: as its penetration rows), so a frame pushed hard
  // out of the object does not buy it with fingers inside each other or past their ranges.
  double constraint_growth = 0;
  // Finger joints as bounded angles (ours, off by default): each joint's flexion, abduction
  // and twist (JointLimits::rotation) are the solver's parameters, bounded by their
  // anatomical ranges, so every step stays inside them (the thumb's box corners, outside its
  // swing, are clamped after each round); twists and PIP/DIP abductions keep the fit's
  // values. false: the axis-angles, within ±π (the paper's). Measured (docs/refinement.md):
  // on generated samples Implaus 98 → 37 %, but hands leave the object less well (Pen 1cm
  // 0.16 → 8.2 %) and less smoothly (Accel 0.043 → 0.133).
  bool joint_angles = false;
  // Steps checked against the exact surface (ours, off by default): the surface is
  // linearised per round, and a step can carry vertices past planes they had none of. After
  // each round, a frame whose deepest vertex ends deeper than it started and than
  // pen_tolerance takes half its step, a quarter, or none, faded over 3 frames each side
  // (pinned and kept frames excepted). Measured (docs/refinement.md): on corrupted ground
  // truth Pen 5mm 1.0 → 0.5 %; on generated samples it holds back frames that needed their
  // step (Pen 1cm 0.16 → 2.9 %, Accel 0.043 → 0.137), so it stays off.
  bool backtrack = false;
  void validate() const;       // throws bimart::Error naming the option
};

// What an animator fixed (core/directing/, docs/directing.md), as the refinement keeps it:
//   pins       per hand, frames whose wrist joint (and orientation, finger pose) is held
//              by w_pin · (||wrist − pin||² + ||log(R_pin^T R)||² + ||θ − θ_pin||²);
//   clearance  per hand and frame, metres the hand keeps off the object there: its
//              penetration planes move out by it (so the penetration term and its growing
//              weight keep every vertex that far out) and its keypoints are not projected
//              onto the surface;
//   kept       frames whose starting state is kept as it is (not optimised): the frames
//              outside a regenerated stretch, which the others then join smoothly;
//   may_hold, may_hold_top  [N, 2] bool: the hands the hold term may pull onto the object
//              (its top part) in each frame; undefined: both.
struct RefineDirections {
  struct Pin {
    std::int64_t frame = 0;
    Eigen::Vector3d wrist = Eigen::Vector3d::Zero();  // world, m
    std::optional<Eigen::Matrix3d> rotation;          // world: the hand's global orientation
    std::optional<Eigen::VectorXd> fingers;           // [45] finger pose (rad)
  };
  std::array<std::vector<Pin>, 2> pins;
  std::array<std::vector<double>, 2> clearance;  // N per hand, or empty: none
  std::vector<bool> kept;                        // N, or empty: none
  at::Tensor may_hold, may_hold_top;
  // N per hand, or empty: the part (ObjectPart) a directed contact asks the hand to touch in
  // each frame, -1 none; the hold term (w_hold) keeps it there, held frame or not.
  std::array<std::vector<int>, 2> hold;
  double w_pin = 1e4;  // per pinned frame, not averaged: a pin outweighs the frame's other terms
  bool empty() const {
    return pins[0].empty() && pins[1].empty() && clearance[0].empty() && clearance[1].empty() && kept.empty() &&
           !may_hold.defined() && !may_hold_top.defined() && hold[0].empty() && hold[1].empty();
  }
};

// The terms of the cost as defined above, weighted, with exact surface distances.
struct RefineTerms {
  double proj = 0, pen = 0, acc = 0, fit = 0, hold = 0, pin = 0, limits = 0, pose = 0, separation = 0;
  double total() const { return proj + pen + acc + fit + hold + pin + limits + pose + separation; }
};
struct RefineHandReport {
  RefineTerms before, after;
  double max_depth_before = 0, max_depth_after = 0;  // m, deepest vertex over all frames
  double keypoint_error_after = 0;                   // m, mean ||K − Ĥ||
  int iterations = 0;                                // LM steps over all outer iterations
  int outer_iterations = 0;
  double max_pen_boost = 1;                          // largest weight multiplier reached
  int held_frames = 0;                               // frames this hand was held in
  int clamped_joints = 0;                            // joints put back into their ranges, all rounds
  int backtracked_frames = 0;                        // frames whose step was cut back, all rounds
  int separation_frames_added = 0;                   // frames given the separation term within a round
  double seconds = 0;
  double surface_seconds = 0;  // of which: surface queries and linearisation
};
struct RefineReport {
  std::array<RefineHandReport, 2> hands;
  double seconds = 0;
};

// keypoints X [N, 1200] (canonical frame, DESIGN §4), states [N, 7], start: a fit (world
// frame), `distance`: the object's (built once per object), `held`: where the hold
// term applies (core/metrics/held_frames.h; empty: nowhere), `directions`: what an animator
// fixed (above). Returns the refined motion with posed vertices. Throws bimart::Error for
// inputs whose shapes disagree.
HandMotion refine_hands(const std::array<const HandModel*, 2>& models, const ObjectDistance& distance, const at::Tensor& states,
                        const at::Tensor& keypoints, const HandMotion& start,
                        const RefineOptions& options = {}, RefineReport* report = nullptr,
                        const HeldFrames& held = {}, const RefineDirections& directions = {});

// One line per hand: the terms before → after, depth and keypoint error (for logs).
std::string format_refine_report(const RefineReport& report);

}  // namespace bimart
