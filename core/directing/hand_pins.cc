#include "core/directing/hand_pins.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <fmt/format.h>

#include <Eigen/SVD>
#include <cmath>

#include "core/features/hand_features.h"
#include "core/hand/keypoints.h"
#include "core/hand/lbs.h"

namespace bimart {
namespace {

Points3 rows_of(const Points3& m, const std::vector<int>& ids) {
  Points3 out(static_cast<Eigen::Index>(ids.size()), 3);
  for (std::size_t i = 0; i < ids.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = m.row(ids[i]);
  return out;
}

// Keypoints [J, 3] of a pose pin's hand at its source frame, in the object's canonical
// frame there.
HandPins::Keys source_keypoints(const HandModel& model, const HandPin& pin) {
  const PinnedPose src = read_pinned_pose(pin);
  const LbsResult<double> r = lbs<double>(model, src.rot, src.pose, src.trans, src.shape);
  const Eigen::Isometry3d to_canonical = src.object.inverse();
  const std::vector<int> ids = model_keypoints(model);
  HandPins::Keys k(static_cast<Eigen::Index>(ids.size()), 3);
  for (std::size_t i = 0; i < ids.size(); ++i)
    k.row(static_cast<Eigen::Index>(i)) = (to_canonical * Eigen::Vector3d(r.vertices.row(ids[i]).transpose())).cast<float>().transpose();
  return k;
}

}  // namespace

HandPins::HandPins(const HandConstraints& constraints, const std::array<const HandModel*, 2>& hands,
                   const at::Tensor& states, const at::Tensor& object_points, double sigma)
    : states_(states.to(at::kDouble).contiguous()), points_(object_points.to(at::kFloat).contiguous()), sigma_(sigma) {
  const std::int64_t N = states_.size(0);
  if (!(sigma >= 0)) throw Error("hand pins: sigma must be >= 0 (frames)");
  for (int h = 0; h < 2; ++h) {
    const HandModel& m = *hands[static_cast<std::size_t>(h)];
    const std::vector<int> ids = model_keypoints(m), part = hand_parts(m);
    std::vector<int> palm_rows, palm_ids;
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (part[static_cast<std::size_t>(ids[i])] == 0) palm_rows.push_back(static_cast<int>(i)), palm_ids.push_back(ids[i]);
    if (palm_rows.size() < 3) throw Error("hand pins: the hand model has fewer than 3 keypoints on the palm");
    const Eigen::VectorXd zero_pose = Eigen::VectorXd::Zero(HandModel::kPoseDim), zero_shape = Eigen::VectorXd::Zero(HandModel::kNumBetas);
    const LbsResult<double> rest = lbs<double>(m, Eigen::Vector3d::Zero(), zero_pose, Eigen::Vector3d::Zero(), zero_shape);
    Palm& p = palms_[static_cast<std::size_t>(h)];
    p.rest = rows_of(rest.vertices, palm_ids);
    p.wrist = rest.joints.row(0).transpose();
    p.index = palm_rows;
  }
  for (const HandPin& pin : constraints.pins) {
    if (pin.frames.last >= N)
      throw Error(pin.where, fmt::format("frames up to {}, but the trajectory has {} frames", pin.frames.last, N));
    Keys pose;
    if (pin.whole_pose())
      pose = source_keypoints(*hands[static_cast<std::size_t>(pin.hand)], pin);
    for (std::int64_t f = pin.frames.first; f <= pin.frames.last; ++f) {
      const Eigen::Isometry3d to_canonical = object_pose_at(states_, f).inverse();
      Target t;
      t.hand = pin.hand;
      t.frame = f;
      t.keypoints = pose;
      if (pin.wrist) t.wrist = to_canonical * *pin.wrist;
      if (pin.rotation) t.turn = true, t.rotation = to_canonical.linear() * pin.rotation->toRotationMatrix();
      targets_.push_back(t);
    }
  }
  for (const ContactConstraint& c : constraints.contacts)
    if (c.part == ContactPart::None) {
      if (c.frames.last >= N)
        throw Error(c.where, fmt::format("frames up to {}, but the trajectory has {} frames", c.frames.last, N));
      away_.push_back(c);
      const FrameRange span = c.with_ramps(N);
      for (std::int64_t f = span.first; f <= span.last; ++f) {
        if (trees_.count(f)) continue;
        const at::Tensor pd = points_[f].to(at::kDouble).contiguous();
        Points3 pts = Eigen::Map<const Points3>(pd.data_ptr<double>(), pd.size(0), 3);
        centres_[f] = pts.colwise().mean().transpose();
        trees_.emplace(f, NearestPoints(std::move(pts)));
      }
    }
}

std::pair<Eigen::Matrix3d, Eigen::Vector3d> HandPins::fit_palm(const Eigen::Ref<const Keys>& keypoints, int hand) const {
  const Palm& palm = palms_[static_cast<std::size_t>(hand)];
  Points3 p(static_cast<Eigen::Index>(palm.index.size()), 3);  // current
  for (std::size_t i = 0; i < palm.index.size(); ++i)
    p.row(static_cast<Eigen::Index>(i)) = keypoints.row(palm.index[i]).cast<double>();
  const Points3& q = palm.rest;
  const Eigen::RowVector3d pc = p.colwise().mean(), qc = q.colwise().mean();
  // Kabsch: R minimising |R (q - qc) - (p - pc)|, a proper rotation.
  const Eigen::Matrix3d cov = (q.rowwise() - qc).transpose() * (p.rowwise() - pc);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d R = svd.matrixV() * fix * svd.matrixU().transpose();
  return {R, R * (palm.wrist - qc.transpose()) + pc.transpose()};
}

std::pair<Eigen::Vector3d, Eigen::Matrix3d> HandPins::wrist_of(const at::Tensor& keypoints, int hand,
                                                               std::int64_t frame) const {
  const at::Tensor k = keypoints.to(at::kFloat).contiguous();
  const auto [R, w] = fit_palm(Eigen::Map<const Keys>(k.data_ptr<float>(), k.size(0), 3), hand);
  const Eigen::Isometry3d to_world = object_pose_at(states_, frame);
  return {to_world * w, to_world.linear() * R};
}

namespace {

// The smallest α ≥ 0 that puts every keypoint k_j + α·d at least `need` from every object
// point. Along the line each keypoint-point pair is too close over an interval of α (the
// roots of |k − p + α d|² = need²); α steps past the end of every interval that holds it
// (the pairs closer than `need` at the current α, from the k-d tree) until none does.
double clearing_shift(const Points3& keys, const Eigen::Vector3d& d, const NearestPoints& tree,
                      double need) {
  // A hand whose keypoints' bounding ball is clear of the nearest point needs nothing.
  // So is, at each α, every keypoint closer to the centre than the centre's distance to the
  // object minus `need` (triangle inequality): only the others ask the k-d tree.
  const Eigen::Vector3d centre = keys.colwise().mean().transpose();
  const Eigen::VectorXd from_centre = (keys.rowwise() - centre.transpose()).rowwise().norm();
  if (std::sqrt(tree.nearest(centre).distance_sq) >= from_centre.maxCoeff() + need) return 0;
  double alpha = 0;
  std::vector<int> hits;
  for (int step = 0; step < 1000; ++step) {
    double next = alpha;
    const double clear_within = std::sqrt(tree.nearest(centre + alpha * d).distance_sq) - need;
    for (Eigen::Index j = 0; j < keys.rows(); ++j) {
      if (from_centre[j] <= clear_within) continue;
      const Eigen::Vector3d k = keys.row(j).transpose();
      tree.within(k + alpha * d, need, &hits);
      for (int i : hits) {
        const Eigen::Vector3d a = k - tree.points().row(i).transpose();
        const double ad = a.dot(d), disc = ad * ad - a.squaredNorm() + need * need;
        if (disc > 0) next = std::max(next, -ad + std::sqrt(disc) + 1e-6);
      }
    }
    if (next == alpha) break;
    alpha = next;
  }
  return alpha;
}

}  // namespace

at::Tensor HandPins::impose(const at::Tensor& x0, std::int64_t first, int /*step*/, int /*num_steps*/) const {
  if (empty()) return x0;
  const std::int64_t B = x0.size(0), T = x0.size(1), J = kHandKeypoints;
  const at::Tensor H = x0.slice(-1, 0, 600).to(at::kFloat).reshape({B, T, 2, J, 3}).contiguous();
  at::Tensor Hn = H.clone();
  const float* const h = H.data_ptr<float>();
  float* const hp = Hn.data_ptr<float>();
  const auto at_hand = [&](std::int64_t b, std::int64_t t, int hand) { return ((b * T + t) * 2 + hand) * J * 3; };
  // Each pinned frame's change [J, 3] per sample, exact there and spread around it (plain
  // loops over the buffers: a step's pins are a few hundred numbers, tensor ops cost more).
  if (!targets_.empty()) {
    std::vector<float> spread(static_cast<std::size_t>(B * T * 2 * J * 3), 0.0f), weight(static_cast<std::size_t>(T * 2), 0.0f);
    std::vector<float> exact(spread.size(), 0.0f);
    std::vector<char> pinned(weight.size(), 0);
    const std::int64_t reach = static_cast<std::int64_t>(std::ceil(3 * sigma_));
    Keys delta(J, 3);
    for (const Target& tg : targets_) {
      const std::int64_t t = tg.frame - first;
      if (t < -reach || t >= T + reach) continue;
      // The pin's change, measured on the frame itself when it is in the window, else on
      // the window's nearest frame (its neighbours still run into it).
      const std::int64_t at_t = std::clamp<std::int64_t>(t, 0, T - 1);
      for (std::int64_t b = 0; b < B; ++b) {
        const Eigen::Map<const Keys> k(h + at_hand(b, at_t, tg.hand), J, 3);
        if (tg.keypoints.size() > 0) {
          delta = tg.keypoints - k;
        } else {
          const auto [R, w] = fit_palm(k, tg.hand);
          const Eigen::Matrix3d turn = tg.turn ? Eigen::Matrix3d(tg.rotation * R.transpose()) : Eigen::Matrix3d::Identity();
          // Turned about the wrist, then the wrist onto the pin.
          const Points3 target = ((k.cast<double>().rowwise() - w.transpose()) * turn.transpose()).rowwise() + tg.wrist.transpose();
          delta = target.cast<float>() - k;
        }
        if (t >= 0 && t < T) {
          std::copy(delta.data(), delta.data() + J * 3, exact.begin() + at_hand(b, t, tg.hand));
          pinned[static_cast<std::size_t>(t * 2 + tg.hand)] = 1;
        }
        if (sigma_ <= 0) continue;
        for (std::int64_t s = std::max<std::int64_t>(0, t - reach); s < std::min(T, t + reach + 1); ++s) {
          const float g = static_cast<float>(std::exp(-0.5 * std::pow(static_cast<double>(s - t) / sigma_, 2)));
          float* out = spread.data() + at_hand(b, s, tg.hand);
          for (std::int64_t i = 0; i < J * 3; ++i) out[i] += g * delta.data()[i];
          if (b == 0) weight[static_cast<std::size_t>(s * 2 + tg.hand)] += g;
        }
      }
    }
    for (std::int64_t b = 0; b < B; ++b)
      for (std::int64_t t = 0; t < T; ++t)
        for (int hand = 0; hand < 2; ++hand) {
          const std::size_t th = static_cast<std::size_t>(t * 2 + hand);
          const std::int64_t o = at_hand(b, t, hand);
          const float scale = 1.0f / std::max(weight[th], 1.0f);
          for (std::int64_t i = 0; i < J * 3; ++i) hp[o + i] += pinned[th] ? exact[o + i] : spread[o + i] * scale;
        }
  }
  // Hands kept off the object: moved rigidly away from the object (from the centre of its
  // points towards the hand's keypoints) until every keypoint is the clearance off every
  // object point. Away from the nearest point alone fails for a hand that is inside the
  // object or wraps it: the nearest point then lies on the far side. On the ramps around the
  // range the clearance fades (ContactConstraint::clearance_at), so the hand lets go and
  // comes back smoothly instead of jumping at the range's ends.
  for (const ContactConstraint& a : away_) {
    const FrameRange span = a.with_ramps(first + T);
    const std::int64_t s0 = std::max(span.first - first, std::int64_t{0}), s1 = span.last - first + 1;
    if (s0 >= s1) continue;
    // Frames (and samples) are independent: spread over the cores.
    at::parallel_for(0, (s1 - s0) * B, 1, [&](std::int64_t begin, std::int64_t end) {
      for (std::int64_t task = begin; task < end; ++task) {
        const std::int64_t s = s0 + task / B, b = task % B, f = first + s;
        const double need = a.clearance_at(f);
        if (need <= 0) continue;
        float* k = hp + ((b * T + s) * 2 + a.hand) * J * 3;  // [J, 3]
        Points3 keys(J, 3);
        for (std::int64_t i = 0; i < J * 3; ++i) keys.data()[i] = k[i];
        Eigen::Vector3d d = keys.colwise().mean().transpose() - centres_.at(f);
        d = d.norm() > 1e-9 ? d.normalized() : Eigen::Vector3d::UnitY();
        const double alpha = clearing_shift(keys, d, trees_.at(f), need);
        for (std::int64_t j = 0; alpha > 0 && j < J; ++j)
          for (int c = 0; c < 3; ++c) k[j * 3 + c] += static_cast<float>(alpha * d[c]);
      }
    });
  }
  const at::Tensor moved = (Hn - H).reshape({B, T, 600});
  return at::cat({Hn.reshape({B, T, 600}), x0.slice(-1, 600, 1200).to(at::kFloat) - moved}, -1).to(x0.scalar_type());
}

}  // namespace bimart
