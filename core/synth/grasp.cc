#include "core/synth/grasp.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/geometry/rotation.h"
#include "core/hand/lbs.h"
#include "core/hand/procedural_hand.h"
#include "core/object/object_state.h"
#include "core/util/error.h"
#include "core/util/log.h"

namespace bimart {
namespace {

constexpr double kTouch = 0.0005;     // a digit "touches" when its deepest vertex is this deep
constexpr double kContact = 0.005;    // contact as the metrics count it (DESIGN §6)
constexpr int kThumb = 4;
// How each digit's first joint turns when the hand fans out (MANO digit order), as in the
// procedural hand's pose samples.
constexpr std::array<double, 5> kFan{1.0, 0.2, -1.4, -0.8, 0.6};

Points3 rows(const Points3& p, const std::vector<int>& ids) {
  Points3 out(static_cast<Eigen::Index>(ids.size()), 3);
  for (size_t i = 0; i < ids.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = p.row(ids[i]);
  return out;
}

}  // namespace

HandGeometry hand_geometry(const HandModel& model, const Eigen::VectorXd& betas) {
  if (betas.size() != HandModel::kNumBetas) throw Error("hand_geometry: expected 10 shape values");
  HandGeometry g;
  g.model = &model;
  g.betas = betas;
  const Eigen::Vector3d zero3 = Eigen::Vector3d::Zero();
  const Eigen::VectorXd zero45 = Eigen::VectorXd::Zero(HandModel::kPoseDim);
  const LbsResult<double> r = lbs<double>(model, zero3, zero45, zero3, betas);
  g.wrist = r.joints.row(0).transpose();
  for (int v = 0; v < model.num_vertices(); ++v) {
    Eigen::Index j;
    model.weights.row(v).maxCoeff(&j);
    if (j == 0) g.palm.push_back(v);
    else g.digits[static_cast<size_t>((j - 1) / 3)].push_back(v);
  }
  // The straight fingers point from the wrist to the middle finger's knuckle; the palm
  // faces -y in MANO's rest frame (both sides: the left hand mirrors x only).
  g.finger_dir = (r.joints.row(4) - r.joints.row(0)).transpose();
  g.palm_normal = Eigen::Vector3d(0, -1, 0);
  g.finger_dir = (g.finger_dir - g.finger_dir.dot(g.palm_normal) * g.palm_normal).normalized();
  // Palm centre: the palm vertices that face the palm's way, averaged.
  TriangleMesh mesh;
  mesh.vertices = r.vertices;
  mesh.faces = model.faces;
  const Eigen::MatrixX3d n = vertex_normals(mesh);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (int v : g.palm)
    if (n.row(v).dot(g.palm_normal) > 0.7) {
      sum += r.vertices.row(v).transpose();
      ++count;
    }
  if (count == 0) throw Error("hand_geometry: the hand model has no palm-side vertices facing -y");
  g.palm_point = sum / count;
  return g;
}

Eigen::VectorXd grasp_finger_pose(const HandGeometry& hand, const std::array<double, 5>& curl, double spread) {
  std::array<double, 5> s{};
  for (int c = 0; c < 5; ++c) s[c] = kFan[c] * spread;
  return procedural_digit_pose(hand.model->side, curl, s);
}

Points3 local_hand_vertices(const HandGeometry& hand, const Eigen::VectorXd& finger_pose) {
  const Eigen::Vector3d zero3 = Eigen::Vector3d::Zero();
  return lbs<double>(*hand.model, zero3, finger_pose, zero3, hand.betas).vertices;
}

GraspPlanner::GraspPlanner(const ArticulatedObject& object, const ObjectDistance& distance)
    : object_(object), distance_(distance) {
  top_ = {ObjectPart::Top, &object.top, vertex_normals(object.top)};
  bottom_ = {ObjectPart::Bottom, &object.bottom, vertex_normals(object.bottom)};
}

const MeshDistance& GraspPlanner::other_part(ObjectPart part) const {
  return part == ObjectPart::Top ? distance_.bottom() : distance_.top();
}

Points3 GraspPlanner::in_other_frame(ObjectPart part, double angle, const Points3& points) const {
  // The top part's frame -> canonical (= the bottom's frame), or back.
  const Eigen::Isometry3d T = part == ObjectPart::Top ? top_to_canonical(angle) : top_to_canonical(angle).inverse();
  return transform_vertices(T, points);
}

double GraspPlanner::depth_other(ObjectPart part, double angle, const Points3& points) const {
  return other_part(part).max_signed_distance(in_other_frame(part, angle, points));
}

double GraspPlanner::depth(ObjectPart part, double angle, const Points3& points) const {
  const MeshDistance& own = part == ObjectPart::Top ? distance_.top() : distance_.bottom();
  return std::max(own.max_signed_distance(points), depth_other(part, angle, points));
}

bool GraspPlanner::deeper_than(ObjectPart part, double angle, const Points3& points, double threshold) const {
  const MeshDistance& own = part == ObjectPart::Top ? distance_.top() : distance_.bottom();
  return own.any_deeper_than(points, threshold) ||
         other_part(part).any_deeper_than(in_other_frame(part, angle, points), threshold);
}

std::optional<Grasp> GraspPlanner::try_site(const HandGeometry& hand, const GraspRequest& req, int vertex,
                                            double wrist_angle, Rng& rng, RejectCounts& counts) const {
  const auto reject = [&](Reject why) -> std::optional<Grasp> {
    ++counts[static_cast<size_t>(why)];
    return std::nullopt;
  };
  const PartSurface& surf = surface(req.part);
  const Eigen::Vector3d site = surf.mesh->vertices.row(vertex).transpose();
  const Eigen::Vector3d normal = surf.normals.row(vertex).transpose();
  if (normal.squaredNorm() < 0.5) return reject(Reject::Normal);

  // Orientation: the palm faces into the surface, the fingers along a tangent at the wrist angle.
  Eigen::Vector3d t0 = normal.unitOrthogonal();
  const Eigen::Vector3d tangent = rotation_about(normal, wrist_angle) * t0;
  Eigen::Matrix3d local, part;
  local << hand.finger_dir, hand.palm_normal, hand.finger_dir.cross(hand.palm_normal);
  part << tangent, -normal, tangent.cross(-normal);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = part * local.transpose();
  const Eigen::Matrix3d world_rotation = req.world_from_part.linear() * T.linear();
  if (req.accept_wrist && !req.accept_wrist(world_rotation, req.world_from_part * site)) return reject(Reject::Wrist);

  // Palm against the surface with the digits straight: bisect the offset along the normal
  // for the deepest vertex to sit at kTouch.
  Grasp g;
  g.part = req.part;
  g.site = site;
  g.normal = normal;
  g.spread = rng.uniform(-0.05, 0.12);
  g.curl = {0, 0, 0, 0, rng.uniform(0.0, 0.3)};
  g.start_curl = g.curl;
  Points3 local_v = local_hand_vertices(hand, grasp_finger_pose(hand, g.curl, g.spread));
  // Deeper than `threshold` into the object or below the table.
  const Eigen::Isometry3d& W = req.world_from_part;
  const bool table = std::isfinite(req.table_height);
  const auto blocked = [&](const Points3& pts, double threshold) {
    if (table)
      for (Eigen::Index i = 0; i < pts.rows(); ++i)
        if (req.table_height - (W * pts.row(i).transpose()).y() > threshold) return true;
    if (deeper_than(req.part, req.angle, pts, threshold)) return true;
    return std::isfinite(req.release_angle) && req.release_angle != req.angle &&
           deeper_than(req.part, req.release_angle, pts, threshold);
  };
  auto place = [&](double offset) {
    Eigen::Isometry3d P = T;
    P.translation() = site + offset * normal - T.linear() * hand.palm_point;
    return P;
  };
  double lo = -0.03, hi = 0.06;  // offsets: lo penetrates, hi is clear
  // Every second vertex is enough to find the offset (the hand's vertices are ~5 mm apart);
  // the finished grasp is checked with all of them.
  Points3 coarse((local_v.rows() + 1) / 2, 3);
  for (Eigen::Index i = 0; i < coarse.rows(); ++i) coarse.row(i) = local_v.row(2 * i);
  // The palm must touch its own part: the other part and the table may only stop it short.
  const MeshDistance& own = req.part == ObjectPart::Top ? distance_.top() : distance_.bottom();
  // Start from a clear pose: 6 cm off the surface, or closer where the table or the other
  // part leaves less room (under an object on a stand).
  while (blocked(transform_vertices(place(hi), coarse), kTouch))
    if ((hi *= 0.5) < 0.007) return reject(Reject::Obstructed);
  if (!own.any_deeper_than(transform_vertices(place(lo), coarse), kTouch)) return reject(Reject::Obstructed);
  for (int it = 0; it < 10; ++it) {  // 9 cm / 2^10: 0.1 mm
    const double mid = 0.5 * (lo + hi);
    (blocked(transform_vertices(place(mid), coarse), kTouch) ? lo : hi) = mid;
  }
  T = place(hi);
  if (own.max_signed_distance(transform_vertices(T, coarse)) < -kContact) return reject(Reject::HeldOff);

  // Close the digits together until each one touches (or reaches its rest curl in the air).
  const std::array<double, 5> limit{1.0, 1.0, 1.0, 1.0, 1.0};
  std::array<double, 5> free_curl{};  // where a digit that touches nothing stops
  for (int c = 0; c < 5; ++c) free_curl[c] = rng.uniform(0.25, 0.6);
  // A digit closes in steps until the next step would push it into the object or the table
  // (then bisected to the touch); one that meets nothing stops at its relaxed curl.
  std::array<double, 5> ok = g.curl, bad{};
  std::array<bool, 5> done{}, hit{};
  auto digits_blocked = [&](const std::array<double, 5>& curl, const std::array<bool, 5>& ask) {
    const Points3 v = transform_vertices(T, local_hand_vertices(hand, grasp_finger_pose(hand, curl, g.spread)));
    std::array<bool, 5> b{};
    for (int c = 0; c < 5; ++c) b[c] = ask[c] && blocked(rows(v, hand.digits[c]), kTouch);
    return b;
  };
  {
    const std::array<bool, 5> all{true, true, true, true, true};
    const auto b0 = digits_blocked(ok, all);
    for (int c = 0; c < 5; ++c)
      if (b0[c]) return reject(Reject::Digit);  // a straight digit already penetrates
  }
  constexpr double kStep = 0.1;
  for (int step = 0; step < 11; ++step) {
    std::array<double, 5> trial = ok;
    std::array<bool, 5> ask{};
    bool any = false;
    for (int c = 0; c < 5; ++c)
      if (!done[c]) trial[c] = std::min(ok[c] + kStep, limit[c]), ask[c] = any = true;
    if (!any) break;
    const auto b = digits_blocked(trial, ask);
    for (int c = 0; c < 5; ++c) {
      if (!ask[c]) continue;
      if (b[c]) {
        bad[c] = trial[c], hit[c] = done[c] = true;
      } else {
        ok[c] = trial[c];
        if (ok[c] >= limit[c] || ok[c] >= free_curl[c] + 0.45) done[c] = true;  // closed in the air
      }
    }
  }
  for (int c = 0; c < 5; ++c)
    if (!hit[c]) ok[c] = std::min(ok[c], std::max(free_curl[c], g.curl[c]));
  for (int it = 0; it < 5; ++it) {  // bisect the touching digits between ok and bad
    std::array<double, 5> trial = ok;
    std::array<bool, 5> ask{};
    bool any = false;
    for (int c = 0; c < 5; ++c)
      if (hit[c]) trial[c] = 0.5 * (ok[c] + bad[c]), ask[c] = any = true;
    if (!any) break;
    const auto b = digits_blocked(trial, ask);
    for (int c = 0; c < 5; ++c)
      if (ask[c]) (b[c] ? bad[c] : ok[c]) = trial[c];
  }
  g.curl = ok;
  g.finger_pose = grasp_finger_pose(hand, g.curl, g.spread);
  g.part_from_hand = T;
  const Points3 v = transform_vertices(T, local_hand_vertices(hand, g.finger_pose));
  const Eigen::VectorXd sd = own.signed_distances(v);
  g.depth = std::max(sd.maxCoeff(), depth_other(req.part, req.angle, v));
  g.contacts = static_cast<int>((sd.array() > -kContact).count());
  if (g.depth > req.max_depth || blocked(v, req.max_depth) || g.contacts < 5) return reject(Reject::Final);
  for (double a : req.hold_angles)  // the other part must not move into the hand
    if (other_part(req.part).any_deeper_than(in_other_frame(req.part, a, v), req.max_depth))
      return reject(Reject::Hinge);
  if (req.accept_hand && !req.accept_hand(v)) return reject(Reject::OtherHand);
  return g;
}

std::optional<Grasp> GraspPlanner::plan(const HandGeometry& hand, const GraspRequest& req, Rng& rng) const {
  if (req.part == ObjectPart::Whole) throw Error("grasp request: the part must be Top or Bottom");
  const PartSurface& surf = surface(req.part);
  const int n = static_cast<int>(surf.mesh->num_vertices());
  std::vector<Grasp> found;
  RejectCounts counts{};
  // The sites the filter accepts, then tries among those only.
  std::vector<int> sites;
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d site = surf.mesh->vertices.row(v).transpose();
    const Eigen::Vector3d normal = surf.normals.row(v).transpose();
    if (!req.accept_site || req.accept_site(site, normal)) sites.push_back(v);
    else ++counts[static_cast<size_t>(Reject::Site)];
  }
  for (int attempt = 0; !sites.empty() && attempt < req.max_tries && static_cast<int>(found.size()) < req.candidates;
       ++attempt) {
    const int v = sites[std::min(sites.size() - 1, static_cast<size_t>(rng.uniform() * static_cast<double>(sites.size())))];
    // A few wrist angles at this site, in random order; the first that works.
    const double start = rng.uniform(0, 2 * M_PI);
    for (int k = 0; k < 6; ++k) {
      if (auto g = try_site(hand, req, v, start + k * (M_PI / 3), rng, counts)) {
        found.push_back(*g);
        break;
      }
    }
  }
  if (found.empty()) {
    static const char* kNames[] = {"site", "normal", "wrist", "obstructed", "held off", "digit", "final",
                                   "hinge", "other hand"};
    std::string text;
    for (size_t i = 0; i < counts.size(); ++i)
      if (counts[i]) text += fmt::format(" {} {}", kNames[i], counts[i]);
    log::debug("grasp planner: no grasp on the {} part; rejected:{}", req.part == ObjectPart::Top ? "top" : "bottom", text);
    return std::nullopt;
  }
  // More contact is a firmer grasp; the jitter keeps the choice varied.
  size_t best = 0;
  double best_score = -1;
  for (size_t i = 0; i < found.size(); ++i) {
    const double score = found[i].contacts * rng.uniform(0.6, 1.0);
    if (score > best_score) best_score = score, best = i;
  }
  return found[best];
}

}  // namespace bimart
