#include "core/synth/interaction.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <ATen/ATen.h>

#include "core/geometry/nearest_points.h"
#include "core/geometry/rotation.h"
#include "core/synth/grasp.h"
#include "core/synth/motion_table.h"
#include "core/object/object_state.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/random.h"

namespace bimart {
namespace {

// Where the person's shoulders are, relative to the object's resting centre: the arms
// reach the object from there, so a wrist must point back towards its own shoulder.
Eigen::Vector3d shoulder(int hand, const Eigen::Vector3d& centre) {
  return Eigen::Vector3d(centre.x() + (hand == 0 ? -0.20 : 0.20), 0.40, centre.z() + 0.45);
}

// Between two hand poses: the rotation slerped about `pivot` (hand local; the palm centre),
// which moves on a straight line, so the palm leaves the surface along the approach line
// instead of swinging through it. The rotation follows its own profile `s_rotation`
// (turned while away from the object, not at it).
Eigen::Isometry3d interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double s,
                              const Eigen::Vector3d& pivot, double s_rotation) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  T.linear() = qa.slerp(s_rotation, qb).toRotationMatrix();
  const Eigen::Vector3d pa = a * pivot, pb = b * pivot;
  T.translation() = pa + s * (pb - pa) - T.linear() * pivot;
  return T;
}

Eigen::Vector3d random_axis(Rng& rng) {
  for (;;) {
    const Eigen::Vector3d v(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    if (v.squaredNorm() > 0.01 && v.squaredNorm() <= 1) return v.normalized();
  }
}

// One hand's plan: its grasp and timing, and the poses it comes from and goes to.
struct HandPlan {
  Grasp grasp;
  int start = 0, grasp_frame = 0, release_frame = 0, end = 0;
  Eigen::Isometry3d pre, post;
  Eigen::VectorXd open_before, open_after;  // finger poses away from the object
};

struct Motion {
  std::array<std::vector<Eigen::Isometry3d>, 2> pose;  // hand local -> world, per frame
  std::array<std::vector<Eigen::VectorXd>, 2> fingers;
  std::array<std::vector<Points3>, 2> vertices;        // world
};

Motion build_motion(const Trajectory& tr, const std::array<HandPlan, 2>& plans,
                    const std::array<HandGeometry, 2>& geo) {
  const int n = tr.num_frames();
  Motion m;
  for (int h = 0; h < 2; ++h) {
    const HandPlan& p = plans[h];
    const Points3 held = local_hand_vertices(geo[h], p.grasp.finger_pose);
    const auto hold_pose = [&](int f) { return world_from_part(tr.states[f], p.grasp.part) * p.grasp.part_from_hand; };
    const Eigen::Isometry3d at_grasp = hold_pose(p.grasp_frame), at_release = hold_pose(p.release_frame);
    for (int f = 0; f < n; ++f) {
      Eigen::Isometry3d T;
      Eigen::VectorXd fingers;
      bool holding = false;
      if (f <= p.start) {
        T = p.pre, fingers = p.open_before;
      } else if (f < p.grasp_frame) {
        const double u = static_cast<double>(f - p.start) / (p.grasp_frame - p.start);
        // Reach (turned on the way), then close the fingers on the surface.
        T = interpolate(p.pre, at_grasp, min_jerk(u / 0.7), geo[h].palm_point, min_jerk(u / 0.5));
        fingers = p.open_before + min_jerk((u - 0.55) / 0.45) * (p.grasp.finger_pose - p.open_before);
      } else if (f <= p.release_frame) {
        T = hold_pose(f), fingers = p.grasp.finger_pose, holding = true;
      } else if (f < p.end) {
        const double u = static_cast<double>(f - p.release_frame) / (p.end - p.release_frame);
        // Open the fingers first (a hooked finger must let go), then leave.
        T = interpolate(at_release, p.post, min_jerk((u - 0.3) / 0.7), geo[h].palm_point, min_jerk((u - 0.5) / 0.5));
        fingers = p.grasp.finger_pose + min_jerk(u / 0.4) * (p.open_after - p.grasp.finger_pose);
      } else {
        T = p.post, fingers = p.open_after;
      }
      m.pose[h].push_back(T);
      m.vertices[h].push_back(transform_vertices(T, holding ? held : local_hand_vertices(geo[h], fingers)));
      m.fingers[h].push_back(std::move(fingers));
    }
  }
  return m;
}

// Empty when the motion passes; otherwise why not.
std::string check_motion(const Trajectory& tr, const ObjectDistance& distance, const Motion& m,
                         const std::array<HandPlan, 2>& plans, const InteractionOptions& o,
                         double* deepest, double* closest) {
  *deepest = -std::numeric_limits<double>::infinity();
  *closest = std::numeric_limits<double>::infinity();
  for (int f = 0; f < tr.num_frames(); ++f) {
    for (int h = 0; h < 2; ++h) {
      const Points3& v = m.vertices[h][f];
      const bool holding = f >= plans[h].grasp_frame && f <= plans[h].release_frame;
      if (v.col(1).minCoeff() < o.table_clearance) return "hand " + std::to_string(h) + " under the table";
      // While held, the hand is rigid with its part and the planner checked it against the
      // other part over the hinge range: every fourth frame suffices as a cross-check.
      if (holding && (f - plans[h].grasp_frame) % 4 != 0 && f != plans[h].release_frame) continue;
      const double d = distance.max_signed_distance(tr.states[f], v);
      *deepest = std::max(*deepest, d);
      if (d > (holding ? o.max_depth + 0.001 : o.max_depth_moving))
        return "hand " + std::to_string(h) + " is " + std::to_string(1000 * d) + " mm deep at frame " +
               std::to_string(f) + (holding ? " (holding)" : f < plans[h].grasp_frame ? " (approaching)" : " (leaving)");
    }
    const NearestPoints left(m.vertices[0][f]);
    const Points3& right = m.vertices[1][f];
    std::vector<int> idx(static_cast<size_t>(right.rows()));
    std::vector<double> d2(static_cast<size_t>(right.rows()));
    left.nearest(right, idx.data(), d2.data());
    const double c = std::sqrt(*std::min_element(d2.begin(), d2.end()));
    *closest = std::min(*closest, c);
    if (c < o.hand_clearance) return "the hands touch at frame " + std::to_string(f);
  }
  return "";
}

}  // namespace

Eigen::Isometry3d world_from_part(const ObjectState& state, ObjectPart part) {
  const Eigen::Isometry3d root = canonical_to_world(state);
  return part == ObjectPart::Top ? root * top_to_canonical(state.angle) : root;
}

HandMotion synthesize_hands(const ArticulatedObject& object, const ObjectDistance& distance,
                            const std::array<const HandModel*, 2>& models, const Trajectory& tr,
                            std::uint64_t seed, const InteractionOptions& o, InteractionInfo* info) {
  const int n = tr.num_frames();
  if (n < 40 || tr.first_move < 12 || tr.last_move + 12 >= n)
    throw Error("synthesize_hands: the trajectory needs >= 12 still frames before and after its motion");
  for (int h = 0; h < 2; ++h)
    if (!models[h] || models[h]->side != (h == 0 ? HandSide::Left : HandSide::Right))
      throw Error("synthesize_hands: models must be {left, right}");
  const GraspPlanner planner(object, distance);
  Rng rng(seed);

  // Object size, at rest, for the role filters.
  const ObjectState rest = tr.states[static_cast<size_t>(tr.first_move)];
  const PosedObject posed = pose_world(object, rest);
  Eigen::Vector3d lo = posed.bottom.colwise().minCoeff().transpose(), hi = posed.bottom.colwise().maxCoeff().transpose();
  lo = lo.cwiseMin(posed.top.colwise().minCoeff().transpose());
  hi = hi.cwiseMax(posed.top.colwise().maxCoeff().transpose());
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double half_x = 0.5 * (hi.x() - lo.x());
  double top_reach = 0;
  for (Eigen::Index i = 0; i < object.top.num_vertices(); ++i)
    top_reach = std::max(top_reach, object.top.vertices.row(i).head<2>().norm());

  // On a stand there is room for a hand underneath (core/synth/motion_table.h).
  const bool on_stand = category_motion(object.category).support >= 0.04;
  const int preferred_driver = rng.chance(0.5) ? 0 : 1;
  std::string last_reason = "no grasp found";
  for (int attempt = 1; attempt <= o.attempts; ++attempt) {
    Rng r(rng.next_seed());
    Eigen::VectorXd betas(HandModel::kNumBetas);  // one person: both hands share the shape
    for (int k = 0; k < betas.size(); ++k) betas[k] = std::clamp(0.4 * r.normal(), -1.0, 1.0);
    const std::array<HandGeometry, 2> geo{hand_geometry(*models[0], betas), hand_geometry(*models[1], betas)};

    std::array<HandPlan, 2> plans;
    int driver = -1;
    std::array<ObjectPart, 2> part{ObjectPart::Bottom, ObjectPart::Bottom};
    if (tr.kind == SequenceKind::Use) {
      // The seed picks the driving hand; only the last attempt tries the other one, so
      // that a hand that is easier to plan for does not win most sequences.
      driver = attempt < o.attempts ? preferred_driver : 1 - preferred_driver;
      part[driver] = ObjectPart::Top;
    }
    const int first_hand = driver >= 0 ? driver : (r.chance(0.5) ? 0 : 1);
    for (int h = 0; h < 2; ++h) {
      HandPlan& p = plans[h];
      p.grasp_frame = std::max(10, tr.first_move - r.integer(0, 3));
      p.start = std::max(0, p.grasp_frame - r.integer(18, 34));
      p.release_frame = std::min(n - 10, tr.last_move + 1 + r.integer(1, 4));
      p.end = std::min(n - 1, p.release_frame + r.integer(18, 34));
    }

    bool planned = true;
    for (int h : {first_hand, 1 - first_hand}) {
      const ObjectState& s = tr.states[static_cast<size_t>(plans[h].grasp_frame)];
      GraspRequest req;
      req.part = part[h];
      req.angle = s.angle;
      req.world_from_part = world_from_part(s, part[h]);
      req.max_depth = o.max_depth;
      req.table_height = o.table_clearance + 0.001;  // the object rests on the table when grasped
      req.release_angle = tr.states[static_cast<size_t>(plans[h].release_frame)].angle;
      {  // the hinge angles passed while held: the range, evenly
        double a_lo = s.angle, a_hi = s.angle;
        for (int f = plans[h].grasp_frame; f <= plans[h].release_frame; ++f)
          a_lo = std::min(a_lo, tr.states[static_cast<size_t>(f)].angle),
          a_hi = std::max(a_hi, tr.states[static_cast<size_t>(f)].angle);
        // Steps small enough that the top part's far end moves at most 4 mm between them.
        const int steps = std::min(90, static_cast<int>(std::ceil((a_hi - a_lo) * top_reach / 0.004)));
        for (int k = 0; k <= steps && a_hi > a_lo; ++k) req.hold_angles.push_back(a_lo + (a_hi - a_lo) * k / steps);
      }
      const bool second = h != first_hand;
      const Grasp* other = second ? &plans[first_hand].grasp : nullptr;
      const Eigen::Isometry3d W_other = second ? world_from_part(s, part[first_hand]) : Eigen::Isometry3d::Identity();
      const bool relaxed = attempt > o.attempts / 2;  // later attempts drop the side preference
      req.accept_site = [&, h, second, other, W_other, relaxed](const Eigen::Vector3d& site, const Eigen::Vector3d& nrm) {
        const Eigen::Isometry3d& W = req.world_from_part;
        const Eigen::Vector3d pw = W * site, nw = W.linear() * nrm;
        if (nw.y() < -0.3 && !on_stand) return false;  // under the object (the table check does the rest)
        if (part[h] == ObjectPart::Top && site.head<2>().norm() < 0.55 * top_reach) return false;
        // Each hand keeps to its side; the driver may reach across (a door's free edge is
        // on one side, and either hand opens it).
        if (!relaxed && h != driver &&
            (h == 0 ? pw.x() - centre.x() > 0.3 * half_x : centre.x() - pw.x() > 0.3 * half_x))
          return false;
        if (second) {
          const Eigen::Vector3d po = W_other * other->site, no = W_other.linear() * other->normal;
          if ((pw - po).norm() < (relaxed ? 0.05 : 0.07)) return false;
          if (tr.kind == SequenceKind::Grab && !relaxed && nw.dot(no) > -0.2) return false;  // opposing sides
        }
        return true;
      };
      const Eigen::Vector3d sh = shoulder(h, centre);
      const Eigen::Vector3d finger_dir = geo[h].finger_dir;
      const double reach = relaxed ? -0.1 : 0.2;  // how squarely the forearm must point at the shoulder
      req.accept_wrist = [sh, finger_dir, reach](const Eigen::Matrix3d& R, const Eigen::Vector3d& pw) {
        return (R * -finger_dir).dot((sh - pw).normalized()) > reach;
      };
      if (second) {  // clear of the first hand at every angle passed while both hold
        const HandPlan& q = plans[first_hand];
        const Points3 first_v = transform_vertices(q.grasp.part_from_hand, local_hand_vertices(geo[first_hand], q.grasp.finger_pose));
        std::vector<double> angles = req.hold_angles;
        angles.push_back(s.angle);
        req.accept_hand = [&, first_v, angles, q](const Points3& v) {
          for (double a : angles) {
            const auto canonical_from = [&](ObjectPart p) {
              return p == ObjectPart::Top ? top_to_canonical(a) : Eigen::Isometry3d::Identity();
            };
            const Eigen::Isometry3d rel = canonical_from(req.part).inverse() * canonical_from(q.grasp.part);
            const NearestPoints tree(transform_vertices(rel, first_v));
            std::vector<int> idx(static_cast<size_t>(v.rows()));
            std::vector<double> d2(static_cast<size_t>(v.rows()));
            tree.nearest(v, idx.data(), d2.data());
            if (std::sqrt(*std::min_element(d2.begin(), d2.end())) < o.hand_clearance + 0.002) return false;
          }
          return true;
        };
      }
      std::optional<Grasp> g = planner.plan(geo[h], req, r);
      if (!g && tr.kind == SequenceKind::Grab) {
        // The bottom may be out of reach (a closed flip phone lies under its top half); with
        // the hinge fixed the object is rigid, so holding the top part carries it as well.
        req.part = part[h] = ObjectPart::Top;
        req.world_from_part = world_from_part(s, ObjectPart::Top);
        g = planner.plan(geo[h], req, r);
      }
      if (!g) {
        planned = false;
        last_reason = std::string("no grasp for the ") + (h == 0 ? "left" : "right") + " hand";
        log::debug("synthesize_hands: plan {} rejected: {}", attempt, last_reason);
        break;
      }
      plans[h].grasp = *g;
    }
    if (!planned) continue;

    // Approach and retreat poses and open finger poses: a few draws for these grasps before
    // planning anew. The hands come from their own side, away from each other.
    Motion m;
    double deepest = 0, closest = 0;
    std::string why = "not tried";
    for (int draw = 0; draw < 4 && !why.empty(); ++draw) {
      for (int h = 0; h < 2; ++h) {
        HandPlan& p = plans[h];
        const auto hold = [&](int f, int hand) {
          const HandPlan& q = plans[hand];
          return world_from_part(tr.states[static_cast<size_t>(f)], q.grasp.part) * q.grasp.part_from_hand;
        };
        const auto away = [&](int f) {
          const Eigen::Isometry3d T = hold(f, h);
          const Eigen::Vector3d nw =
              world_from_part(tr.states[static_cast<size_t>(f)], p.grasp.part).linear() * p.grasp.normal;
          const Eigen::Vector3d to_shoulder = (shoulder(h, centre) - T.translation()).normalized();
          Eigen::Vector3d apart = T.translation() - hold(f, 1 - h).translation();
          apart.y() = 0;
          if (apart.norm() > 1e-6) apart.normalize();
          // Off the surface; from under an object (on a stand) sideways, never down into the table.
          Eigen::Vector3d off = nw;
          if (off.y() < 0) {
            off.y() = 0;
            if (off.norm() < 0.3) off = Eigen::Vector3d(to_shoulder.x(), 0, to_shoulder.z());
            off.normalize();
          }
          Eigen::Vector3d dir =
              (off + 0.6 * Eigen::Vector3d::UnitY() + 0.5 * to_shoulder + (0.4 + 0.3 * draw) * apart).normalized();
          // Mostly off the surface: at least 50° from sliding along it.
          for (int k = 0; k < 8 && dir.dot(off) < 0.65; ++k) dir = (dir + 0.5 * off).normalized();
          // Turned a little about the palm centre, then moved away along `dir`.
          Eigen::Isometry3d A = T;
          A.linear() = rotation_about(random_axis(r), r.uniform(0.05, 0.3)) * T.linear();
          const Eigen::Vector3d palm = T * geo[h].palm_point;
          A.translation() = palm + r.uniform(0.10, 0.25) * dir - A.linear() * geo[h].palm_point;
          return A;
        };
        p.pre = away(p.grasp_frame);
        p.post = away(p.release_frame);
        // Open: on the planner's closing path (checked clear), so opening only lifts the
        // digits off the surface and closing only brings them onto it.
        const auto open = [&] {
          std::array<double, 5> c{};
          for (int k = 0; k < 5; ++k) {
            const double a = p.grasp.start_curl[k], b = std::max(a, p.grasp.curl[k]);
            c[k] = a + r.uniform(0.0, 0.5) * (b - a);
          }
          return grasp_finger_pose(geo[h], c, p.grasp.spread);
        };
        p.open_before = open();
        p.open_after = open();
      }
      m = build_motion(tr, plans, geo);
      why = check_motion(tr, distance, m, plans, o, &deepest, &closest);
      if (!why.empty()) log::debug("synthesize_hands: plan {}, approach {} rejected: {}", attempt, draw, why);
    }
    if (!why.empty()) {
      last_reason = why;
      continue;
    }

    HandMotion out;
    for (int h = 0; h < 2; ++h) {
      HandParams& hp = out.hands[h];
      hp.rot = at::empty({n, 3}, at::kFloat);
      hp.pose = at::empty({n, 45}, at::kFloat);
      hp.trans = at::empty({n, 3}, at::kFloat);
      hp.shape = at::empty({10}, at::kFloat);
      float* rot = hp.rot.data_ptr<float>();
      float* pose = hp.pose.data_ptr<float>();
      float* trans = hp.trans.data_ptr<float>();
      for (int f = 0; f < n; ++f) {
        const Eigen::Isometry3d& T = m.pose[h][f];
        const Eigen::Vector3d aa = matrix_to_axis_angle(T.linear());
        // LBS rotates about the root joint: world = R (v - J0) + J0 + trans.
        const Eigen::Vector3d t = T.translation() + T.linear() * geo[h].wrist - geo[h].wrist;
        for (int k = 0; k < 3; ++k) rot[3 * f + k] = static_cast<float>(aa[k]), trans[3 * f + k] = static_cast<float>(t[k]);
        for (int k = 0; k < 45; ++k) pose[45 * f + k] = static_cast<float>(m.fingers[h][f][k]);
      }
      for (int k = 0; k < 10; ++k) hp.shape.data_ptr<float>()[k] = static_cast<float>(betas[k]);
    }
    if (info) {
      info->driver = driver;
      info->attempts = attempt;
      info->depth = deepest;
      info->clearance = closest;
      for (int h = 0; h < 2; ++h) {
        info->part[h] = part[h];
        info->grasp_frame[h] = plans[h].grasp_frame;
        info->release_frame[h] = plans[h].release_frame;
      }
    }
    return out;
  }
  throw Error("synthesize_hands: no valid motion after " + std::to_string(o.attempts) + " plans (last: " +
              last_reason + ")");
}

}  // namespace bimart
