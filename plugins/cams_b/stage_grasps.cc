#include "stage_grasps.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/features/contact_map.h"
#include "core/geometry/rotation.h"
#include "core/object/object_state.h"
#include "core/synth/grasp.h"
#include "core/synth/interaction.h"
#include "core/util/error.h"
#include "core/util/random.h"

namespace bimart {
namespace {

// A hand's pose in one stage: held on a part (a grasp), or waiting away from the object.
struct StagePose {
  std::optional<Grasp> grasp;
  Eigen::Isometry3d wait = Eigen::Isometry3d::Identity();  // canonical frame, when no grasp
  Eigen::VectorXd fingers;                                 // 45
};

Eigen::Isometry3d world_pose(const StagePose& p, const ObjectState& s) {
  if (p.grasp) return world_from_part(s, p.grasp->part) * p.grasp->part_from_hand;
  return canonical_to_world(s) * p.wait;
}

// Away from the object on the hand's side (left: −x, right: +x of the canonical frame),
// palm towards it, fingers flat.
StagePose waiting(const ArticulatedObject& object, const HandGeometry& geo, int hand) {
  Points3 all(object.top.vertices.rows() + object.bottom.vertices.rows(), 3);
  all << object.top.vertices, object.bottom.vertices;
  const Eigen::Vector3d lo = all.colwise().minCoeff().transpose(), hi = all.colwise().maxCoeff().transpose();
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double side = hand == 0 ? -1.0 : 1.0;
  const Eigen::Vector3d palm_at = centre + Eigen::Vector3d(side * (0.5 * (hi.x() - lo.x()) + 0.12), 0.05, 0);
  // Rotate the palm normal onto the way to the object.
  const Eigen::Vector3d to_object = -side * Eigen::Vector3d::UnitX();
  const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(geo.palm_normal, to_object).toRotationMatrix();
  StagePose p;
  p.wait.linear() = R;
  p.wait.translation() = palm_at - R * geo.palm_point;
  p.fingers = Eigen::VectorXd::Zero(45);
  return p;
}

}  // namespace

HandMotion stage_grasp_hands(const ArticulatedObject& object, const ObjectDistance& distance,
                             const std::array<const HandModel*, 2>& models, const at::Tensor& states_in,
                             const at::Tensor& targets_in, const at::Tensor& hits_in,
                             const std::vector<ManipulationStage>& stages, const StageGraspOptions& o,
                             std::uint64_t seed) {
  const at::Tensor states = states_in.to(at::kDouble).contiguous();
  const at::Tensor targets = targets_in.to(at::kFloat).contiguous();
  const std::int64_t N = states.size(0), M = targets.size(2);
  if (targets.dim() != 3 || targets.size(0) != N || targets.size(1) != 2 || hits_in.dim() != 2 ||
      hits_in.size(0) != N || hits_in.size(1) != M)
    throw Error("CAMS-B hands: need targets [N, 2, M] and hits [N, M] for " + std::to_string(N) + " frames");
  std::vector<ObjectState> s;
  for (std::int64_t t = 0; t < N; ++t) s.push_back(ObjectState::from_row(states.data_ptr<double>() + 7 * t));
  // [N, M, 3] canonical: the target rows' object points.
  const at::Tensor points = basis_hit_points(object, states.to(at::kFloat), hits_in).to(at::kDouble).contiguous();
  const at::Tensor hits = hits_in.to(at::kLong).contiguous();
  const float* tp = targets.data_ptr<float>();
  const double* pp = points.data_ptr<double>();
  const std::int64_t* hp_ = hits.data_ptr<std::int64_t>();
  const std::int64_t top_vertices = object.top.vertices.rows();
  const GraspPlanner planner(object, distance);
  Rng rng(seed);

  HandMotion out;
  for (int h = 0; h < 2; ++h) {
    const HandGeometry geo = hand_geometry(*models[static_cast<std::size_t>(h)], Eigen::VectorXd::Zero(HandModel::kNumBetas));
    std::vector<StagePose> poses;
    for (const ManipulationStage& st : stages) {
      const std::int64_t mid = (st.first + st.last) / 2;
      // The target's contact points, and the part most of them are on.
      Eigen::Vector3d sum[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
      int count[2] = {0, 0};
      for (std::int64_t k = 0; k < M; ++k) {
        if (tp[(mid * 2 + h) * M + k] >= o.contact) continue;
        const int part = hp_[mid * M + k] < top_vertices ? 0 : 1;
        for (int c = 0; c < 3; ++c) sum[part][c] += pp[(mid * M + k) * 3 + c];
        ++count[part];
      }
      std::optional<Grasp> grasp;
      if (count[0] + count[1] > 0) {
        const int part_index = count[0] >= count[1] ? 0 : 1;
        const ObjectPart part = part_index == 0 ? ObjectPart::Top : ObjectPart::Bottom;
        const Eigen::Vector3d centre_canonical = sum[part_index] / count[part_index];
        const Eigen::Vector3d centre = part == ObjectPart::Top
                                           ? Eigen::Vector3d(top_to_canonical(s[static_cast<std::size_t>(mid)].angle).inverse() * centre_canonical)
                                           : centre_canonical;
        GraspRequest req;
        req.part = part;
        req.angle = s[static_cast<std::size_t>(mid)].angle;
        req.world_from_part = world_from_part(s[static_cast<std::size_t>(mid)], part);
        req.max_depth = o.max_depth;
        for (std::int64_t f = st.first; f <= st.last; f += 4) req.hold_angles.push_back(s[static_cast<std::size_t>(f)].angle);
        for (const double radius : {o.site_radius, 2 * o.site_radius, 1e9}) {
          req.accept_site = [centre, radius](const Eigen::Vector3d& site, const Eigen::Vector3d&) {
            return (site - centre).norm() < radius;
          };
          grasp = planner.plan(geo, req, rng);
          if (grasp) break;
        }
      }
      StagePose p = grasp ? StagePose{grasp, Eigen::Isometry3d::Identity(), grasp->finger_pose} : waiting(object, geo, h);
      poses.push_back(std::move(p));
    }
    // Per frame: the stage's pose, blended into the next stage's around each boundary.
    HandParams& hp = out.hands[static_cast<std::size_t>(h)];
    hp.rot = at::empty({N, 3}, at::kFloat);
    hp.pose = at::empty({N, 45}, at::kFloat);
    hp.trans = at::empty({N, 3}, at::kFloat);
    hp.shape = at::zeros({HandModel::kNumBetas}, at::kFloat);
    float* rot = hp.rot.data_ptr<float>();
    float* pose = hp.pose.data_ptr<float>();
    float* trans = hp.trans.data_ptr<float>();
    for (std::size_t k = 0; k < stages.size(); ++k)
      for (std::int64_t f = stages[k].first; f <= stages[k].last; ++f) {
        const ObjectState& sf = s[static_cast<std::size_t>(f)];
        Eigen::Isometry3d T = world_pose(poses[k], sf);
        Eigen::VectorXd fingers = poses[k].fingers;
        // Within blend/2 of the next stage's first frame: towards its pose (smoothstep).
        const std::int64_t half = o.blend / 2;
        if (k + 1 < stages.size() && half > 0 && f > stages[k].last - half) {
          const double u = static_cast<double>(f - (stages[k].last - half)) / static_cast<double>(2 * half);
          const double w = u * u * (3 - 2 * u);
          const Eigen::Isometry3d U = world_pose(poses[k + 1], sf);
          const Eigen::Quaterniond q = Eigen::Quaterniond(T.linear()).slerp(w, Eigen::Quaterniond(U.linear()));
          T.translation() = (1 - w) * T.translation() + w * U.translation();
          T.linear() = q.toRotationMatrix();
          fingers = (1 - w) * fingers + w * poses[k + 1].fingers;
        } else if (k > 0 && half > 0 && f < stages[k].first + half) {
          const double u = 0.5 + static_cast<double>(f - stages[k].first) / static_cast<double>(2 * half);
          const double w = u * u * (3 - 2 * u);
          const Eigen::Isometry3d P = world_pose(poses[k - 1], sf);
          const Eigen::Quaterniond q = Eigen::Quaterniond(P.linear()).slerp(w, Eigen::Quaterniond(T.linear()));
          T.translation() = (1 - w) * P.translation() + w * T.translation();
          T.linear() = q.toRotationMatrix();
          fingers = (1 - w) * poses[k - 1].fingers + w * fingers;
        }
        const Eigen::Vector3d aa = matrix_to_axis_angle(T.linear());
        // LBS rotates about the root joint: world = R (v - J0) + J0 + trans (as the engine writes hands).
        const Eigen::Vector3d t = T.translation() + T.linear() * geo.wrist - geo.wrist;
        for (int c = 0; c < 3; ++c) rot[3 * f + c] = static_cast<float>(aa[c]), trans[3 * f + c] = static_cast<float>(t[c]);
        for (int c = 0; c < 45; ++c) pose[45 * f + c] = static_cast<float>(fingers[c]);
      }
  }
  return out;
}

}  // namespace bimart
