#include "core/refine/refinement.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <map>
#include <optional>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include <ATen/ATen.h>
#include <fmt/format.h>

#include "core/features/hand_features.h"
#include "core/geometry/point_guard.h"
#include "core/hand/finger_separation.h"
#include "core/hand/joint_limits.h"
#include "core/hand/regressed_joints.h"
#include "core/hand/keypoints.h"
#include "core/hand/lbs.h"
#include "core/hand/lbs_subset.h"
#include "core/metrics/frame_depths.h"
#include "core/refine/exit_plane.h"
#include "core/refine/hand_state.h"
#include "core/refine/mano_fit.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/parallel.h"

namespace bimart {
namespace {

constexpr int kJ = 100;
constexpr int kX = kHandStateSize;
constexpr double kLeverFinger = 0.03;  // m: finger angles as lengths (as the MANO fit)
constexpr double kClearanceTolerance = 0.0005;  // m
// m: pen_fingers_through moves a vertex through a part at most this far (a finger's tip
// beyond a thin part: the margin, 1.5 cm, and a part as thick as a finger).
constexpr double kThroughReach = 0.03;
constexpr int kSeparationPasses = 2;  // re-solves per round for frames that came near the gap
using Jet = ceres::Jet<double, kX>;

// One frame's linearisation: the vertices posed (keypoints first, then the acceleration
// vertices, then those near the object) and the tangent planes.
struct FrameTerms {
  LbsSubset sub;
  std::vector<int> pen_rows;    // subset rows with a penetration plane
  std::vector<Plane> pen;       // their planes
  std::vector<double> pen_scale;  // their residual scales (s_pen × the vertex's boost)
  std::vector<double> pen_offset;  // m their planes are moved out by (the frame's clearance)
  std::array<Plane, kJ> proj;   // per keypoint: the plane nearest K + D̂
  std::vector<double> pos, jac;  // posed [3S] and d/dx [3S × 51] at the current point
  int hold_k = -1;               // held frame: the keypoint pulled onto the surface
  Plane hold;                    // its plane
};

struct HandData {
  const HandModel* model = nullptr;
  int64_t N = 0;
  std::vector<double> x, beta;  // [N × 51], [10]
  std::vector<double> H, D;     // targets, world frame [N × 300]
  std::vector<ObjectState> states;
  std::vector<int> kp_ids, acc_ids;  // vertex ids
  std::vector<int> acc_rows;         // row of each acceleration vertex in every frame's subset
  std::vector<FrameTerms> frames;
  double s_fit = 0, s_proj = 0, s_pen = 0, s_acc = 0, s_hold = 0;  // residual scales (√weight/count)
  std::vector<int> hold_part;  // per frame: -1, or the ObjectPart this hand is held to
  // Per frame: the penetration weight multiplier (grows while the frame stays too deep).
  std::vector<double> pen_boost;
  // Per frame: a vertex was found in a cavity behind a wall (pen_cavities) in some round; its
  // inside vertices then leave towards the rest of the hand whatever their depth.
  std::vector<bool> through_wall;
  std::vector<int> finger_of;  // per row of the all-vertex subset: vertex_fingers
  // Directions (RefineDirections): per frame clearance (m) and kept flags, the pins, the
  // wrist joint of the rest hand with this β (the wrist is at trans + j0), √(2 w_pin).
  std::vector<double> clearance;
  std::vector<bool> kept;
  std::vector<RefineDirections::Pin> pins;
  Eigen::Vector3d j0 = Eigen::Vector3d::Zero();
  double s_pin = 0;
  std::optional<JointLimits> limits;  // the model's; residual scale √(2 w_limits / N) · ℓ_f
  double s_limits = 0;
  std::vector<double> p_start;  // [N × 51] the start's parameters (w_pose), s_pose √(2 w_pose / N) · ℓ_f
  double s_pose = 0;
  RegressedJoints rj;  // the joints as the measure reads them (w_separation), residual scale √(2 w_separation / N)
  double s_sep = 0;
  // What Ceres optimises, [N × 51]: x itself, or with RefineOptions::joint_angles x with
  // each finger joint's axis-angle as its three bounded angles (JointLimits::rotation).
  bool angles = false;
  std::vector<double> p;
  bool is_kept(int64_t t) const { return !kept.empty() && kept[static_cast<size_t>(t)]; }
};

// Frame state x (axis-angles) from parameters p, templated for Jets; and back.
template <class T>
void state_of(const HandData& d, const T* p, T* x) {
  if (!d.angles) {
    std::copy(p, p + kX, x);
    return;
  }
  std::copy(p, p + 3, x);
  std::copy(p + 48, p + kX, x + 48);
  for (int j = 0; j < 15; ++j) d.limits->rotation(j, p + 3 + 3 * j, x + 3 + 3 * j);
}
void params_of(const HandData& d, const double* x, double* p) {
  std::copy(x, x + kX, p);
  if (!d.angles) return;
  for (int j = 0; j < 15; ++j) {
    const Eigen::Vector3d a = d.limits->parameters(j, Eigen::Vector3d(x[3 + 3 * j], x[4 + 3 * j], x[5 + 3 * j]));
    std::copy(a.data(), a.data() + 3, p + 3 + 3 * j);
  }
}

// One finger's anatomical joint limits in one frame: its three joints' excess, from their
// parameters (axis-angles, or bounded angles).
struct FingerLimitCost {
  const JointLimits* limits;
  int finger;
  double scale;
  bool angles;
  template <class T>
  bool operator()(const T* p9, T* r) const {
    T aa[9];
    for (int k = 0; k < 3; ++k)
      if (angles)
        limits->rotation(3 * finger + k, p9 + 3 * k, aa + 3 * k);
      else
        std::copy(p9 + 3 * k, p9 + 3 * k + 3, aa + 3 * k);
    limits->scaled_excess(3 * finger, 3, aa, scale, r);
    return true;
  }
};

// Fingers apart in one frame (core/hand/finger_separation.h), from its five finger blocks
// (axis-angles, or bounded angles): distances within the hand do not depend on the global
// rotation and translation, so they stay out of the block.
struct FingerSeparationCost {
  const HandData* d;
  double gap, scale;
  template <class T>
  bool operator()(const T* f0, const T* f1, const T* f2, const T* f3, const T* f4, T* r) const {
    T p[kX], x[kX];
    for (int i = 0; i < kX; ++i) p[i] = T(0);
    const T* fingers[5] = {f0, f1, f2, f3, f4};
    for (int g = 0; g < 5; ++g) std::copy(fingers[g], fingers[g] + 9, p + 3 + 9 * g);
    state_of(*d, p, x);
    T tip[5][3], J[HandModel::kNumJoints][3];
    d->rj.pose(x, d->beta.data(), J, tip);
    finger_separation_shortfall<T>(J, tip, gap, r);
    for (int i = 0; i < kFingerSeparationResiduals; ++i) r[i] *= T(scale);
    return true;
  }
};

// Frame t's separation shortfalls (m, max(0, gap − distance)) at the current x.
void separation_shortfall(const HandData& d, int64_t t, double gap, double* r) {
  double tip[5][3], J[HandModel::kNumJoints][3];
  d.rj.pose(d.x.data() + t * kX, d.beta.data(), J, tip);
  finger_separation_shortfall<double>(J, tip, gap, r);
}

// Σ_t Σ_pairs max(0, gap − d)² (m²) of the hand's current poses.
double separation_sum(const HandData& d, double gap) {
  double sum = 0, r[kFingerSeparationResiduals];
  for (int64_t t = 0; t < d.N; ++t) {
    separation_shortfall(d, t, gap, r);
    for (double v : r) sum += v * v;
  }
  return sum;
}

// Whether frame t's fingers come within kSeparationActive of the gap (the term's active set).
bool near_gap(const HandData& d, int64_t t, double gap) {
  double r[kFingerSeparationResiduals];
  separation_shortfall(d, t, gap + kSeparationActive, r);
  return *std::max_element(r, r + kFingerSeparationResiduals) > 0;
}

// Σ_t Σ_j ||excess||² (rad²) of the hand's current poses.
double limit_excess_sum(const HandData& d) {
  double sum = 0;
  for (int64_t t = 0; t < d.N; ++t) sum += d.limits->squared_excess(d.x.data() + t * kX + 3);
  return sum;
}

// Poses every frame once per evaluation point (x from the parameters p), with Jacobians
// (with respect to p) when asked.
class PoseCache : public ceres::EvaluationCallback {
 public:
  explicit PoseCache(HandData* d) : d_(d) {}
  void PrepareForEvaluation(bool jacobians, bool new_point) override {
    if (!new_point && (have_jacobians_ || !jacobians)) return;
    for (int64_t t = 0; t < d_->N; ++t) {
      FrameTerms& f = d_->frames[static_cast<size_t>(t)];
      double* x = d_->x.data() + t * kX;
      const double* p = d_->p.data() + t * kX;
      if (!d_->is_kept(t)) state_of(*d_, p, x);
      const int R = 3 * f.sub.size();
      f.pos.resize(static_cast<size_t>(R));
      if (jacobians) {
        Jet pj[kX], xj[kX];
        for (int i = 0; i < kX; ++i) pj[i] = Jet(p[i], i);
        state_of(*d_, pj, xj);
        std::vector<Jet> out(static_cast<size_t>(R));
        lbs_subset(f.sub, xj, xj + 3, xj + 48, d_->beta.data(), out.data());
        f.jac.resize(static_cast<size_t>(R) * kX);
        for (int r = 0; r < R; ++r) {
          f.pos[static_cast<size_t>(r)] = out[static_cast<size_t>(r)].a;
          std::copy(out[static_cast<size_t>(r)].v.data(), out[static_cast<size_t>(r)].v.data() + kX,
                    f.jac.data() + static_cast<size_t>(r) * kX);
        }
      } else {
        lbs_subset(f.sub, x, x + 3, x + 48, d_->beta.data(), f.pos.data());
      }
    }
    have_jacobians_ = jacobians;
  }

 private:
  HandData* d_;
  bool have_jacobians_ = false;
};

// Row of the Jacobian of subset vertex s, coordinate k.
inline const double* jac_row(const FrameTerms& f, int s, int k) {
  return f.jac.data() + static_cast<size_t>(3 * s + k) * kX;
}

// A vertex moves with the global rotation and translation and with the fingers its
// skinning weights (and pose correctives) reach. Each frame's state is split into Ceres
// parameter blocks — rot (3), one per finger (9: its three joints), trans (3) — and every
// residual block reads only the blocks its vertices move with: the normal equations
// then skip the zeros a whole-hand block would carry (a fingertip row has 15 columns,
// not 51), several times fewer operations.
struct Block {
  int offset, size;  // in the 51-vector
};
std::vector<Block> blocks_of(unsigned mask) {
  std::vector<Block> b{{0, 3}};
  for (int f = 0; f < 5; ++f)
    if (mask & (1u << f)) b.push_back({3 + 9 * f, 9});
  b.push_back({48, 3});
  return b;
}
std::vector<double*> block_pointers(double* x, const std::vector<Block>& blocks) {
  std::vector<double*> p;
  for (const Block& b : blocks) p.push_back(x + b.offset);
  return p;
}

// Per model vertex: bit f set when finger f (MANO order: index, middle, pinky, ring,
// thumb; joints 1 + 3f .. 3 + 3f) moves it.
std::vector<unsigned> finger_masks(const HandModel& m) {
  const int V = m.num_vertices();
  std::vector<unsigned> mask(static_cast<size_t>(V), 0u);
  for (int i = 0; i < V; ++i)
    for (int j = 1; j < HandModel::kNumJoints; ++j) {
      bool moves = m.weights(i, j) != 0.0;
      for (int e = 0; e < 9 && !moves; ++e)
        for (int k = 0; k < 3 && !moves; ++k) moves = m.posedirs(3 * i + k, 9 * (j - 1) + e) != 0.0;
      if (moves) mask[static_cast<size_t>(i)] |= 1u << ((j - 1) / 3);
    }
  return mask;
}

// Writes scale · (row vector `src`, 51 entries) into the residual row `row` of every block.
inline void write_row(const double* src, double scale, const std::vector<Block>& blocks, int row, double** J,
                      int first_block = 0) {
  for (size_t b = 0; b < blocks.size(); ++b) {
    double* dst = J[first_block + static_cast<int>(b)];
    if (!dst) continue;
    dst += row * blocks[b].size;
    for (int c = 0; c < blocks[b].size; ++c) dst[c] = scale * src[blocks[b].offset + c];
  }
}

// n · (d position of subset vertex s / dx): the row of a point-to-plane residual.
inline void normal_row(const FrameTerms& f, int s, const Eigen::Vector3d& n, double* dst) {
  const double *a = jac_row(f, s, 0), *b = jac_row(f, s, 1), *c = jac_row(f, s, 2);
  for (int i = 0; i < kX; ++i) dst[i] = n.x() * a[i] + n.y() * b[i] + n.z() * c[i];
}

// Fit, projection and penetration rows of one frame's vertices that share a finger mask;
// reads the cache.
class FrameCost : public ceres::CostFunction {
 public:
  FrameCost(const HandData* d, int64_t t, std::vector<Block> blocks, std::vector<int> keypoints,
            std::vector<int> pens)
      : d_(d), t_(t), blocks_(std::move(blocks)), kps_(std::move(keypoints)), pens_(std::move(pens)) {
    set_num_residuals(4 * static_cast<int>(kps_.size()) + static_cast<int>(pens_.size()));
    for (const Block& b : blocks_) mutable_parameter_block_sizes()->push_back(b.size);
  }
  bool Evaluate(double const* const*, double* r, double** J) const override {
    const FrameTerms& f = d_->frames[static_cast<size_t>(t_)];
    const double* H = d_->H.data() + t_ * 3 * kJ;
    const double* D = d_->D.data() + t_ * 3 * kJ;
    double n_row[kX];
    int row = 0;
    for (int k : kps_)
      for (int c = 0; c < 3; ++c, ++row) {
        r[row] = d_->s_fit * (f.pos[static_cast<size_t>(3 * k + c)] - H[3 * k + c]);
        if (J) write_row(jac_row(f, k, c), d_->s_fit, blocks_, row, J);
      }
    // A frame the hand keeps off the object has no contacts to project onto.
    const double s_proj = d_->clearance[static_cast<size_t>(t_)] > 0 ? 0.0 : d_->s_proj;
    for (int k : kps_) {
      const Plane& p = f.proj[static_cast<size_t>(k)];
      const Eigen::Vector3d P(f.pos[3 * k] + D[3 * k], f.pos[3 * k + 1] + D[3 * k + 1], f.pos[3 * k + 2] + D[3 * k + 2]);
      r[row] = s_proj * p.normal.dot(P - p.point);
      if (J) {
        normal_row(f, k, p.normal, n_row);
        write_row(n_row, s_proj, blocks_, row, J);
      }
      ++row;
    }
    for (int i : pens_) {
      const int s = f.pen_rows[static_cast<size_t>(i)];
      const Plane& p = f.pen[static_cast<size_t>(i)];
      const Eigen::Vector3d v(f.pos[3 * s], f.pos[3 * s + 1], f.pos[3 * s + 2]);
      const double depth = p.normal.dot(p.point - v) + f.pen_offset[static_cast<size_t>(i)];
      const double scale = f.pen_scale[static_cast<size_t>(i)];
      r[row] = depth > 0 ? scale * depth : 0.0;
      if (J) {
        normal_row(f, s, p.normal, n_row);
        write_row(n_row, depth > 0 ? -scale : 0.0, blocks_, row, J);
      }
      ++row;
    }
    return true;
  }

 private:
  const HandData* d_;
  int64_t t_;
  std::vector<Block> blocks_;
  std::vector<int> kps_, pens_;  // keypoint indices; indices into the frame's pen rows
};

// Second differences over frames t−2, t−1, t of the acceleration vertices that share a
// finger mask (the same subset rows in every frame).
class AccelCost : public ceres::CostFunction {
 public:
  AccelCost(const HandData* d, int64_t t, std::vector<Block> blocks, std::vector<int> rows)
      : d_(d), t_(t), blocks_(std::move(blocks)), rows_(std::move(rows)) {
    set_num_residuals(3 * static_cast<int>(rows_.size()));
    for (int i = 0; i < 3; ++i)
      for (const Block& b : blocks_) mutable_parameter_block_sizes()->push_back(b.size);
  }
  bool Evaluate(double const* const*, double* r, double** J) const override {
    const FrameTerms* f[3] = {&d_->frames[static_cast<size_t>(t_ - 2)], &d_->frames[static_cast<size_t>(t_ - 1)],
                              &d_->frames[static_cast<size_t>(t_)]};
    const double w[3] = {1.0, -2.0, 1.0};
    const int nb = static_cast<int>(blocks_.size());
    int row = 0;
    for (int s : rows_)
      for (int c = 0; c < 3; ++c, ++row) {
        double v = 0;
        for (int i = 0; i < 3; ++i) v += w[i] * f[i]->pos[static_cast<size_t>(3 * s + c)];
        r[row] = d_->s_acc * v;
        if (J)
          for (int i = 0; i < 3; ++i) write_row(jac_row(*f[i], s, c), d_->s_acc * w[i], blocks_, row, J, i * nb);
      }
    return true;
  }

 private:
  const HandData* d_;
  int64_t t_;
  std::vector<Block> blocks_;
  std::vector<int> rows_;
};

// The hold row of one frame: its keypoint's distance outside the surface plane (0 inside).
class HoldCost : public ceres::CostFunction {
 public:
  HoldCost(const HandData* d, int64_t t, std::vector<Block> blocks) : d_(d), t_(t), blocks_(std::move(blocks)) {
    set_num_residuals(1);
    for (const Block& b : blocks_) mutable_parameter_block_sizes()->push_back(b.size);
  }
  bool Evaluate(double const* const*, double* r, double** J) const override {
    const FrameTerms& f = d_->frames[static_cast<size_t>(t_)];
    const int k = f.hold_k;
    const Eigen::Vector3d v(f.pos[3 * k], f.pos[3 * k + 1], f.pos[3 * k + 2]);
    const double out = f.hold.normal.dot(v - f.hold.point);
    r[0] = out > 0 ? d_->s_hold * out : 0.0;
    if (J) {
      double row[kX];
      normal_row(f, k, f.hold.normal, row);
      write_row(row, out > 0 ? d_->s_hold : 0.0, blocks_, 0, J);
    }
    return true;
  }

 private:
  const HandData* d_;
  int64_t t_;
  std::vector<Block> blocks_;
};

// N pinned values of one parameter block: r = s (x − target). The wrist's translation
// block (target: the pin minus j0) and each finger's block (its three joints).
template <int N>
class ValuePinCost : public ceres::SizedCostFunction<N, N> {
 public:
  ValuePinCost(const double* target, double s) : s_(s) { std::copy(target, target + N, target_); }
  bool Evaluate(double const* const* x, double* r, double** J) const override {
    for (int c = 0; c < N; ++c) r[c] = s_ * (x[0][c] - target_[c]);
    if (J && J[0])
      for (int i = 0; i < N * N; ++i) J[0][i] = i % (N + 1) == 0 ? s_ : 0.0;
    return true;
  }

 private:
  double target_[N];
  double s_;
};

// A pinned orientation: r = s · log(R_pin^T R(rot)) as an axis-angle vector.
struct RotationPin {
  Eigen::Matrix3d pin;
  double s;
  template <class T>
  bool operator()(const T* aa, T* r) const {
    T R[9], M[9];
    ceres::AngleAxisToRotationMatrix(aa, ceres::RowMajorAdapter3x3(R));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        M[3 * i + j] = T(0);
        for (int k = 0; k < 3; ++k) M[3 * i + j] += pin(k, i) * R[3 * k + j];
      }
    ceres::RotationMatrixToAngleAxis(ceres::RowMajorAdapter3x3(static_cast<const T*>(M)), r);
    for (int c = 0; c < 3; ++c) r[c] *= s;
    return true;
  }
};

// The pins' cost w_pin · Σ (wrist², rotation², fingers²) at the current x.
double pin_cost(const HandData& d, double w_pin) {
  double sum = 0;
  for (const RefineDirections::Pin& p : d.pins) {
    const double* x = d.x.data() + p.frame * kX;
    sum += (Eigen::Vector3d(x[48], x[49], x[50]) + d.j0 - p.wrist).squaredNorm();
    if (p.rotation) {
      double r[3];
      RotationPin{*p.rotation, 1.0}(x, r);
      sum += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    }
    if (p.fingers)
      for (int i = 0; i < 45; ++i) sum += std::pow(x[3 + i] - (*p.fingers)[i], 2);
  }
  return w_pin * sum;
}

Points3 pose_all(const LbsSubset& all, const double* x, const double* beta) {
  Points3 v(all.size(), 3);
  lbs_subset(all, x, x + 3, x + 48, beta, v.data());
  return v;
}

Plane plane_of(const ObjectSurfaceQuery& q) { return Plane{q.closest, q.normal}; }

struct Evaluation {
  RefineTerms terms;
  double max_depth = 0;
  double keypoint_error = 0;
  double max_boost = 1;
  int64_t deepest_frame = -1;
  int deepest_vertex = -1;
};

// The cost's terms with exact distances at the current x; optionally re-linearises.
// With `grow`, frames deeper than the tolerance get their penetration weight multiplied.
// In a frame with a clearance c, depths are measured from the surface moved out by c.
Evaluation evaluate(HandData* d, const LbsSubset& all, const ObjectDistance& dist,
                    const RefineOptions& o, bool relinearise, bool grow = false, double w_pin = 0) {
  const int64_t N = d->N;
  const int V = all.size();
  Evaluation e;
  double proj = 0, pen = 0, acc = 0, fit = 0, hold = 0, kerr = 0;
  std::vector<Points3> acc_points;
  // Kept for the penetration planes, built after every frame's way out is known.
  std::vector<Points3> frame_v(relinearise ? static_cast<size_t>(N) : 0);
  std::vector<std::vector<std::pair<int, ObjectSurfaceQuery>>> frame_near(frame_v.size());
  std::vector<double> frame_depths(frame_v.size(), 0.0);
  std::vector<Eigen::Vector3d> exits(frame_v.size(), Eigen::Vector3d::Zero());
  std::vector<std::vector<std::pair<int, Plane>>> frame_cavity(frame_v.size());  // pen_cavities
  for (int64_t t = 0; t < N; ++t) {
    const Points3 v = pose_all(all, d->x.data() + t * kX, d->beta.data());
    const ObjectState& st = d->states[static_cast<size_t>(t)];
    const double* H = d->H.data() + t * 3 * kJ;
    const double* D = d->D.data() + t * 3 * kJ;
    FrameTerms* f = relinearise ? &d->frames[static_cast<size_t>(t)] : nullptr;
    const double clear = d->clearance[static_cast<size_t>(t)];
    for (int k = 0; k < kJ; ++k) {
      const Eigen::Vector3d K = v.row(d->kp_ids[static_cast<size_t>(k)]).transpose();
      const Eigen::Vector3d Ht(H[3 * k], H[3 * k + 1], H[3 * k + 2]), Dt(D[3 * k], D[3 * k + 1], D[3 * k + 2]);
      fit += (K - Ht).squaredNorm();
      kerr += (K - Ht).norm();
      const ObjectSurfaceQuery q = dist.query(st, K + Dt);
      if (clear == 0) proj += q.signed_distance * q.signed_distance;
      if (f) f->proj[static_cast<size_t>(k)] = plane_of(q);
    }
    if (d->hold_part[static_cast<size_t>(t)] >= 0) {  // the keypoint nearest the part
      const auto part = static_cast<ObjectPart>(d->hold_part[static_cast<size_t>(t)]);
      ObjectSurfaceQuery best;
      int best_k = -1;
      for (int k = 0; k < kJ; ++k) {
        const ObjectSurfaceQuery q = dist.query(st, v.row(d->kp_ids[static_cast<size_t>(k)]).transpose(), part);
        if (best_k < 0 || q.signed_distance > best.signed_distance) best = q, best_k = k;
      }
      if (best.signed_distance < 0) hold += best.signed_distance * best.signed_distance;
      if (f) {
        f->hold_k = best_k;
        f->hold = plane_of(best);
      }
    }
    const auto near = dist.near_surface(st, v, (relinearise ? o.pen_margin : 0.0) + clear);
    for (const auto& [i, q] : near)
      if (q.signed_distance + clear > 0) {
        const double depth = q.signed_distance + clear;
        pen += depth * depth;
        if (depth > e.max_depth) {
          e.max_depth = depth;
          e.deepest_frame = t;
          e.deepest_vertex = i;
        }
      }
    Points3 a(static_cast<Eigen::Index>(d->acc_ids.size()), 3);
    for (size_t i = 0; i < d->acc_ids.size(); ++i) a.row(static_cast<Eigen::Index>(i)) = v.row(d->acc_ids[i]);
    acc_points.push_back(std::move(a));
    std::vector<int> inside;
    for (const auto& [i, q] : near)
      if (q.signed_distance > 0) inside.push_back(i);
    // Vertices in a hollow part's cavity (pen_cavities) behind a wall from the rest of the
    // hand: the wall between is a penetration the signed distance cannot see (a finger
    // through a box's 5 mm wall is at most 2.5 mm inside it). Each gets the plane where a
    // ray from it towards the rest of the hand leaves the wall, at its depth behind it;
    // one whose ray meets nothing (the way is open: reaching in through the opening) none.
    std::vector<std::pair<int, Plane>> cavity_planes;
    Eigen::Vector3d cavity_way = Eigen::Vector3d::Zero();
    double cavity_depth = 0;
    if (o.pen_cavities) {
      const auto cavity = dist.cavity_points(st, v, kCavityFloor);
      if (!cavity.empty()) {
        std::vector<int> trapped = inside;
        trapped.insert(trapped.end(), cavity.begin(), cavity.end());
        cavity_way = exit_direction(v, trapped);
        for (const int i : cavity) {
          if (cavity_way.isZero()) break;
          const Eigen::Vector3d p = v.row(i).transpose();
          const std::optional<Plane> wall = exit_plane_through(dist, st, p, cavity_way);
          if (!wall) continue;
          const double depth = wall->normal.dot(wall->point - p) + clear;
          if (depth <= 0) continue;
          cavity_planes.emplace_back(i, *wall);
          pen += depth * depth;
          cavity_depth = std::max(cavity_depth, depth);
          if (depth > e.max_depth) {
            e.max_depth = depth;
            e.deepest_frame = t;
            e.deepest_vertex = i;
          }
        }
      }
    }
    if (!f) continue;
    frame_v[static_cast<size_t>(t)] = v;
    frame_near[static_cast<size_t>(t)] = near;
    double frame_depth = cavity_depth;
    for (const auto& [i, q] : near) frame_depth = std::max(frame_depth, q.signed_distance + clear);
    frame_depths[static_cast<size_t>(t)] = frame_depth;
    // A deep frame's inside vertices leave towards the hand's outside (exit_direction),
    // not each to its nearest surface: in a part thinner than twice their depth the
    // nearest side flips between vertices and rounds, and the hand stays stuck in it. A
    // frame with a finger through a wall leaves through it the same way as its cavity
    // vertices.
    if (!cavity_planes.empty()) {
      exits[static_cast<size_t>(t)] = cavity_way;
      d->through_wall[static_cast<size_t>(t)] = true;
    } else if (frame_depth > o.pen_exit_depth || d->through_wall[static_cast<size_t>(t)]) {
      exits[static_cast<size_t>(t)] = exit_direction(v, inside);
    }
    frame_cavity[static_cast<size_t>(t)] = std::move(cavity_planes);
  }
  // With pen_exit_smooth k: the way out of each frame within k frames of a deep one (and
  // with a vertex inside) is the mean of the deep frames' ways out within k frames. Frame by
  // frame it can point up in one frame and down the next (a hand around a thin part's
  // edge), and a frame just under pen_exit_depth takes nearest planes beside one just over
  // it: either way the hand leaves each frame its own way, in jumps.
  if (relinearise && o.pen_exit_smooth > 0) {
    const std::vector<Eigen::Vector3d> raw = exits;
    for (int64_t t = 0; t < N; ++t) {
      if (frame_depths[static_cast<size_t>(t)] <= 0) continue;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int64_t u = std::max<int64_t>(0, t - o.pen_exit_smooth); u <= std::min(N - 1, t + o.pen_exit_smooth); ++u)
        sum += raw[static_cast<size_t>(u)];
      if (sum.norm() > 1e-9) exits[static_cast<size_t>(t)] = sum.normalized();
    }
  }
  for (int64_t t = 0; relinearise && t < N; ++t) {
    FrameTerms* f = &d->frames[static_cast<size_t>(t)];
    const Points3& v = frame_v[static_cast<size_t>(t)];
    const auto& near = frame_near[static_cast<size_t>(t)];
    const ObjectState& st = d->states[static_cast<size_t>(t)];
    const double clear = d->clearance[static_cast<size_t>(t)];
    const double frame_depth = frame_depths[static_cast<size_t>(t)];
    const Eigen::Vector3d& exit = exits[static_cast<size_t>(t)];
    // The frame's subset: keypoints, acceleration vertices, near vertices (no repeats).
    std::vector<int> ids = d->kp_ids, row_of(static_cast<size_t>(V), -1);
    for (int k = 0; k < kJ; ++k) row_of[static_cast<size_t>(ids[static_cast<size_t>(k)])] = k;
    auto row_for = [&](int vid) {
      int& r = row_of[static_cast<size_t>(vid)];
      if (r < 0) {
        r = static_cast<int>(ids.size());
        ids.push_back(vid);
      }
      return r;
    };
    if (t == 0) {
      d->acc_rows.clear();
      for (int vid : d->acc_ids) d->acc_rows.push_back(row_for(vid));
    } else {
      for (int vid : d->acc_ids) row_for(vid);  // the same rows in every frame
    }
    f->pen_rows.clear();
    f->pen.clear();
    f->pen_scale.clear();
    f->pen_offset.clear();
    double& boost = d->pen_boost[static_cast<size_t>(t)];
    // A clearance is a promise to the animator (`bimart constraints` allows it 1 mm): its
    // frames grow their weight from kClearanceTolerance on, not from pen_tolerance.
    const double tolerance = clear > 0 ? std::min(o.pen_tolerance, kClearanceTolerance) : o.pen_tolerance;
    if (grow && frame_depth > tolerance) boost = std::min(boost * o.pen_growth, std::max(o.max_pen_boost, 1.0));
    e.max_boost = std::max(e.max_boost, boost);
    const auto& cavity = frame_cavity[static_cast<size_t>(t)];
    std::array<bool, 6> finger_inside{};  // pen_fingers_through: fingers (and palm) with a vertex inside
    if (o.pen_fingers_through && !exit.isZero())
      for (const auto& [i, q] : near)
        if (q.signed_distance > 0) finger_inside[static_cast<size_t>(d->finger_of[static_cast<size_t>(i)])] = true;
    std::vector<bool> has_wall(cavity.empty() ? 0 : static_cast<size_t>(V), false);  // most frames: none
    for (const auto& [i, wall] : cavity) {
      has_wall[static_cast<size_t>(i)] = true;
      f->pen_rows.push_back(row_for(all.vertex_ids[static_cast<size_t>(i)]));
      f->pen.push_back(wall);
      f->pen_scale.push_back(d->s_pen * boost);
      f->pen_offset.push_back(clear);
    }
    for (const auto& [i, q] : near) {
      // A cavity vertex's plane is beyond the wall: its nearest (the wall's inner face,
      // facing the cavity) would hold it back there.
      if (!has_wall.empty() && has_wall[static_cast<size_t>(i)]) continue;
      f->pen_rows.push_back(row_for(all.vertex_ids[static_cast<size_t>(i)]));
      const bool turn = !exit.isZero() && q.normal.dot(exit) < 0;
      const Eigen::Vector3d p = v.row(i).transpose();
      std::optional<Plane> out;
      if (turn && q.signed_distance > 0) out = exit_plane(dist, st, p, exit);
      // A frame through a wall: a vertex still in the cavity, near the wall's inside face,
      // passes through the wall too (that face's plane would hold it in the box).
      else if (turn && d->through_wall[static_cast<size_t>(t)] && dist.cavity_depth(st, p) > 0)
        out = exit_plane_through(dist, st, p, exit);
      // A finger through a thin part: its vertices beyond the part go back through it with
      // the rest of the finger (the nearest face would hold them beyond).
      else if (turn && finger_inside[static_cast<size_t>(d->finger_of[static_cast<size_t>(i)])]) {
        out = exit_plane_through(dist, st, p, exit);
        if (out && out->normal.dot(out->point - p) > kThroughReach) out.reset();
      }
      f->pen.push_back(out ? *out : plane_of(q));  // no exit within reach: the nearest surface
      f->pen_scale.push_back(d->s_pen * boost);
      f->pen_offset.push_back(clear);
    }
    f->sub = LbsSubset::from(*d->model, ids);
  }
  for (int64_t t = 2; t < N; ++t)
    acc += (acc_points[static_cast<size_t>(t)] - 2 * acc_points[static_cast<size_t>(t - 1)] +
            acc_points[static_cast<size_t>(t - 2)]).rowwise().squaredNorm().sum();
  const double nk = static_cast<double>(N * kJ);
  e.terms.proj = o.w_proj * proj / nk;
  e.terms.pen = o.w_pen * pen / nk;
  e.terms.fit = o.w_fit * fit / nk;
  e.terms.hold = o.w_hold * hold / static_cast<double>(N);
  e.terms.pin = pin_cost(*d, w_pin);
  e.terms.limits = o.w_limits * kLeverFinger * kLeverFinger * limit_excess_sum(*d) / static_cast<double>(N);
  if (o.w_pose > 0) {
    double sq = 0;
    std::vector<double> q(kX);
    for (int64_t t = 0; t < N; ++t) {
      params_of(*d, d->x.data() + t * kX, q.data());
      for (int i = 3; i < 48; ++i) sq += std::pow(q[static_cast<size_t>(i)] - d->p_start[static_cast<size_t>(t * kX + i)], 2);
    }
    e.terms.pose = o.w_pose * kLeverFinger * kLeverFinger * sq / static_cast<double>(N);
  }
  if (o.w_separation > 0) e.terms.separation = o.w_separation * separation_sum(*d, o.separation_gap) / static_cast<double>(N);
  e.terms.acc = N > 2 ? o.w_acc * acc / static_cast<double>((N - 2) * static_cast<int64_t>(d->acc_ids.size())) : 0.0;
  e.keypoint_error = kerr / nk;
  return e;
}

// With bounded joint angles, the angles each round holds (SubsetManifold): the passive ones —
// every joint's twist and the PIP's and DIP's abduction stay as the fit set them (free, the
// solver turns them to their edges, ±20°, to slip vertices out, and converges slower:
// docs/refinement.md) — and, as an active-set method would, those on an edge that the
// cost's gradient pushes outwards (Ceres keeps bounds by projecting each step onto the box:
// a step computed as if such a joint could go on is cut there, Levenberg–Marquardt rejects
// it and shrinks its region, and the round stalls).
void hold_angles(ceres::Problem* problem, HandData* d) {
  std::vector<double*> blocks;
  for (int64_t t = 0; t < d->N; ++t)
    for (int g = 0; g < 5; ++g) {
      double* b = d->p.data() + t * kX + 3 + 9 * g;
      if (problem->HasParameterBlock(b) && !problem->IsParameterBlockConstant(b)) blocks.push_back(b);
    }
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = blocks;
  double cost = 0;
  std::vector<double> gradient;
  problem->Evaluate(eo, &cost, nullptr, &gradient, nullptr);
  for (size_t b = 0; b < blocks.size(); ++b) {
    std::vector<int> held;
    for (int i = 0; i < 9; ++i) {
      const double x = blocks[b][i], g = gradient[9 * b + static_cast<size_t>(i)];
      const double lo = problem->GetParameterLowerBound(blocks[b], i), hi = problem->GetParameterUpperBound(blocks[b], i);
      constexpr double kEdge = 1e-9;  // rad
      const bool passive = i % 3 == 2 || i == 4 || i == 7;  // a twist, or a PIP's or DIP's abduction
      if (passive || (x <= lo + kEdge && g > 0) || (x >= hi - kEdge && g < 0)) held.push_back(i);
    }
    if (held.size() == 9)
      problem->SetParameterBlockConstant(blocks[b]);
    else if (!held.empty())
      problem->SetManifold(blocks[b], new ceres::SubsetManifold(9, held));
  }
}

// The surface enters each round linearised, and a step can carry vertices past planes they
// had none of (a finger curled 70° into the part it touched). So each frame whose deepest
// vertex (exact distance, beyond its clearance) would end deeper than it started and than
// the tolerance takes half its step, a quarter, or none; the cut fades in and out over
// kFade frames each side (a minimum, then a mean: never more than a frame's own share), so
// the motion stays smooth (cut frame by frame, Accel rose 0.044 → 0.289 on generated
// samples); a frame the faded share still takes too deep takes none. Kept and pinned frames
// keep their step. Returns the frames cut back.
int backtrack(HandData* d, const LbsSubset& all, const ObjectDistance& dist, const RefineOptions& o,
              const std::vector<double>& p_before) {
  constexpr int64_t kFade = 3;
  const int64_t N = d->N;
  std::vector<bool> fixed(static_cast<size_t>(N), false);
  for (int64_t t = 0; t < N; ++t) fixed[static_cast<size_t>(t)] = d->is_kept(t);
  for (const RefineDirections::Pin& p : d->pins) fixed[static_cast<size_t>(p.frame)] = true;
  std::vector<double> x(kX), p(kX), limit(static_cast<size_t>(N), 0.0), share(static_cast<size_t>(N), 1.0);
  // Frame t's parameters a share of the way from the round's start to the solver's point.
  const auto blend = [&](int64_t t, double a) {
    const double *pb = p_before.data() + t * kX, *pt = d->p.data() + t * kX;
    for (int i = 0; i < kX; ++i) p[static_cast<size_t>(i)] = pb[i] + a * (pt[i] - pb[i]);
    return p.data();
  };
  const auto depth = [&](int64_t t, const double* params) {
    state_of(*d, params, x.data());
    return dist.max_signed_distance(d->states[static_cast<size_t>(t)], pose_all(all, x.data(), d->beta.data())) +
           d->clearance[static_cast<size_t>(t)];
  };
  bool any = false;
  for (int64_t t = 0; t < N; ++t) {
    if (fixed[static_cast<size_t>(t)]) continue;
    limit[static_cast<size_t>(t)] = std::max(depth(t, p_before.data() + t * kX), o.pen_tolerance);
    for (const double a : {1.0, 0.5, 0.25, 0.0})
      if (a == 0.0 || depth(t, blend(t, a)) <= limit[static_cast<size_t>(t)]) {
        share[static_cast<size_t>(t)] = a;
        any |= a < 1.0;
        break;
      }
  }
  if (!any) return 0;
  std::vector<double> low(static_cast<size_t>(N)), faded(static_cast<size_t>(N));
  for (int64_t t = 0; t < N; ++t) {
    low[static_cast<size_t>(t)] = 1.0;
    for (int64_t u = std::max<int64_t>(0, t - kFade); u <= std::min(N - 1, t + kFade); ++u)
      low[static_cast<size_t>(t)] = std::min(low[static_cast<size_t>(t)], share[static_cast<size_t>(u)]);
  }
  for (int64_t t = 0; t < N; ++t) {
    double sum = 0;
    int n = 0;
    for (int64_t u = std::max<int64_t>(0, t - kFade); u <= std::min(N - 1, t + kFade); ++u, ++n) sum += low[static_cast<size_t>(u)];
    faded[static_cast<size_t>(t)] = sum / n;
  }
  int cut = 0;
  for (int64_t t = 0; t < N; ++t) {
    double a = faded[static_cast<size_t>(t)];
    if (fixed[static_cast<size_t>(t)] || a >= 1.0) continue;
    if (depth(t, blend(t, a)) > limit[static_cast<size_t>(t)]) a = 0.0;
    const double* q = blend(t, a);
    std::copy(q, q + kX, d->p.data() + t * kX);
    state_of(*d, d->p.data() + t * kX, d->x.data() + t * kX);
    ++cut;
  }
  return cut;
}

void refine_hand(HandData* d, const ObjectDistance& dist, const RefineOptions& o, RefineHandReport* rep,
                 double w_pin) {
  const auto t0 = std::chrono::steady_clock::now();
  const int V = d->model->num_vertices();
  std::vector<int> all_ids(static_cast<size_t>(V));
  for (int i = 0; i < V; ++i) all_ids[static_cast<size_t>(i)] = i;
  const LbsSubset all = LbsSubset::from(*d->model, all_ids);
  const std::vector<unsigned> masks = finger_masks(*d->model);
  d->frames.assign(static_cast<size_t>(d->N), FrameTerms{});
  const double nk = static_cast<double>(d->N * kJ);
  d->s_fit = std::sqrt(2 * o.w_fit / nk);  // Ceres minimises ½Σr²
  d->s_proj = std::sqrt(2 * o.w_proj / nk);
  d->s_acc = d->N > 2 ? std::sqrt(2 * o.w_acc / static_cast<double>((d->N - 2) * static_cast<int64_t>(d->acc_ids.size())))
                      : 0.0;

  auto timed_evaluate = [&](bool relinearise, bool grow) {
    const auto s0 = std::chrono::steady_clock::now();
    Evaluation ev = evaluate(d, all, dist, o, relinearise, grow, w_pin);
    rep->surface_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
    return ev;
  };
  d->s_pen = std::sqrt(2 * o.w_pen / nk);
  d->s_hold = std::sqrt(2 * o.w_hold / static_cast<double>(d->N));
  d->s_pin = std::sqrt(2 * w_pin);
  d->s_limits = std::sqrt(2 * o.w_limits / static_cast<double>(d->N)) * kLeverFinger;
  d->s_pose = std::sqrt(2 * o.w_pose / static_cast<double>(d->N)) * kLeverFinger;
  d->s_sep = std::sqrt(2 * o.w_separation / static_cast<double>(d->N));
  d->rj = RegressedJoints::from(*d->model);
  d->p_start.resize(d->x.size());
  for (int64_t t = 0; t < d->N; ++t) params_of(*d, d->x.data() + t * kX, d->p_start.data() + t * kX);
  for (int p : d->hold_part) rep->held_frames += p >= 0;
  d->pen_boost.assign(static_cast<size_t>(d->N), 1.0);
  d->through_wall.assign(static_cast<size_t>(d->N), false);
  const std::vector<int> fingers = vertex_fingers(*d->model);
  d->finger_of.clear();
  for (const int vid : all.vertex_ids) d->finger_of.push_back(fingers[static_cast<size_t>(vid)]);
  Evaluation e = timed_evaluate(o.outer_iterations > 0, false);
  rep->before = e.terms;
  rep->max_depth_before = e.max_depth;
  const int max_outer = std::max(o.outer_iterations, o.max_outer_iterations);
  for (int outer = 0; outer < max_outer; ++outer) {
    if (outer >= o.outer_iterations && (e.max_depth <= o.pen_tolerance || o.w_pen == 0)) break;
    d->p.resize(d->x.size());
    for (int64_t t = 0; t < d->N; ++t) params_of(*d, d->x.data() + t * kX, d->p.data() + t * kX);
    PoseCache cache(d);
    ceres::Problem::Options po;
    po.evaluation_callback = &cache;
    ceres::Problem problem(po);
    std::vector<bool> separated(static_cast<size_t>(d->N), false);  // frames with the separation term
    const auto add_separation = [&](int64_t t, double grown) {
      double* x = d->p.data() + t * kX;
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<FingerSeparationCost, kFingerSeparationResiduals, 9, 9, 9, 9, 9>(
              new FingerSeparationCost{d, o.separation_gap, d->s_sep * grown}),
          nullptr, x + 3, x + 12, x + 21, x + 30, x + 39);
      separated[static_cast<size_t>(t)] = true;
    };
    // Acceleration rows by finger mask (the same in every frame).
    std::map<unsigned, std::vector<int>> acc_groups;
    for (size_t a = 0; a < d->acc_ids.size(); ++a)
      acc_groups[masks[static_cast<size_t>(d->acc_ids[a])]].push_back(d->acc_rows[a]);
    for (int64_t t = 0; t < d->N; ++t) {
      const FrameTerms& f = d->frames[static_cast<size_t>(t)];
      std::map<unsigned, std::pair<std::vector<int>, std::vector<int>>> groups;  // keypoints, pens
      for (int k = 0; k < kJ; ++k) groups[masks[static_cast<size_t>(d->kp_ids[static_cast<size_t>(k)])]].first.push_back(k);
      for (size_t i = 0; i < f.pen_rows.size(); ++i)
        groups[masks[static_cast<size_t>(f.sub.vertex_ids[static_cast<size_t>(f.pen_rows[i])])]].second.push_back(
            static_cast<int>(i));
      double* x = d->p.data() + t * kX;
      for (auto& [mask, g] : groups) {
        const std::vector<Block> blocks = blocks_of(mask);
        problem.AddResidualBlock(new FrameCost(d, t, blocks, std::move(g.first), std::move(g.second)), nullptr,
                                 block_pointers(x, blocks));
      }
      if (f.hold_k >= 0 && o.w_hold > 0) {
        const std::vector<Block> blocks = blocks_of(masks[static_cast<size_t>(d->kp_ids[static_cast<size_t>(f.hold_k)])]);
        problem.AddResidualBlock(new HoldCost(d, t, blocks), nullptr, block_pointers(x, blocks));
      }
      const double grown = std::pow(d->pen_boost[static_cast<size_t>(t)], o.constraint_growth);
      if (o.w_limits > 0)  // with bounded angles, only the thumb's box corners can be outside
        for (int g = d->angles ? 4 : 0; g < 5; ++g)
          problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FingerLimitCost, 9, 9>(
                                       new FingerLimitCost{&*d->limits, g, d->s_limits * grown, d->angles}),
                                   nullptr, x + 3 + 9 * g);
      if (o.w_pose > 0 && !d->is_kept(t))
        for (int g = 0; g < 5; ++g)
          problem.AddResidualBlock(new ValuePinCost<9>(d->p_start.data() + t * kX + 3 + 9 * g, d->s_pose), nullptr,
                                   x + 3 + 9 * g);
      if (o.w_separation > 0 && !d->is_kept(t) && near_gap(*d, t, o.separation_gap)) add_separation(t, grown);
      if (t < 2 || o.w_acc == 0) continue;
      for (const auto& [mask, rows] : acc_groups) {
        const std::vector<Block> blocks = blocks_of(mask);
        std::vector<double*> p;
        for (int64_t u = t - 2; u <= t; ++u)
          for (double* q : block_pointers(d->p.data() + u * kX, blocks)) p.push_back(q);
        problem.AddResidualBlock(new AccelCost(d, t, blocks, rows), nullptr, p);
      }
    }
    // A pinned frame's fingers: their target as parameters, which its bounds then include.
    std::map<int64_t, std::vector<double>> pinned_fingers;
    for (const RefineDirections::Pin& p : d->pins) {
      double* x = d->p.data() + p.frame * kX;
      const Eigen::Vector3d trans = p.wrist - d->j0;
      problem.AddResidualBlock(new ValuePinCost<3>(trans.data(), d->s_pin), nullptr, x + 48);
      if (p.rotation)
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<RotationPin, 3, 3>(new RotationPin{*p.rotation, d->s_pin}),
                                 nullptr, x);
      if (p.fingers) {
        std::vector<double> state(kX, 0.0), target(kX);
        std::copy(p.fingers->data(), p.fingers->data() + 45, state.data() + 3);
        params_of(*d, state.data(), target.data());
        for (int g = 0; g < 5; ++g)
          problem.AddResidualBlock(new ValuePinCost<9>(target.data() + 3 + 9 * g, d->s_pin), nullptr, x + 3 + 9 * g);
        pinned_fingers[p.frame] = std::move(target);
      }
    }
    // Kept frames stay as they started: every block of theirs constant.
    for (int64_t t = 0; t < d->N; ++t) {
      if (!d->is_kept(t)) continue;
      double* x = d->p.data() + t * kX;
      for (const Block& b : blocks_of(0x1f))
        if (problem.HasParameterBlock(x + b.offset)) problem.SetParameterBlockConstant(x + b.offset);
    }
    // Bounds keep a hand that the penetration boost pushes hard from winding its joints
    // round and round (generated keypoints 5 cm deep once drove a finger angle to 1,100 rad):
    // the root's axis-angle within ±2π; the fingers' angles within their ranges
    // (JointLimits::bounds; a pinned frame's widened to its pin), or their axis-angle
    // components within ±π.
    for (int64_t t = 0; t < d->N; ++t) {
      if (d->is_kept(t)) continue;
      double* x = d->p.data() + t * kX;
      const auto pin = pinned_fingers.find(t);
      for (const Block& b : blocks_of(0x1f)) {
        if (b.offset == 48 || !problem.HasParameterBlock(x + b.offset)) continue;  // translation: free
        for (int i = 0; i < b.size; ++i) {
          const int k = b.offset + i;  // in the 51-vector
          double lo = b.offset == 0 ? -2 * M_PI : -M_PI, hi = -lo;
          if (b.offset > 0 && d->angles) {
            const AngleRange r = d->limits->bounds((k - 3) / 3)[static_cast<size_t>((k - 3) % 3)];
            lo = r.lo;
            hi = r.hi;
            if (pin != pinned_fingers.end()) {
              lo = std::min(lo, pin->second[static_cast<size_t>(k)]);
              hi = std::max(hi, pin->second[static_cast<size_t>(k)]);
            }
          }
          x[k] = std::clamp(x[k], lo, hi);
          problem.SetParameterLowerBound(x + b.offset, i, lo);
          problem.SetParameterUpperBound(x + b.offset, i, hi);
        }
      }
    }
    if (d->angles) hold_angles(&problem, d);
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    so.max_num_iterations = o.max_iterations;
    so.num_threads = 1;  // one hand per thread
    so.logging_type = ceres::SILENT;
    so.function_tolerance = 1e-8;
    ceres::Solver::Summary summary;
    const std::vector<double> p_before = d->p;
    const auto solve = [&] {
      ceres::Solve(so, &problem, &summary);
      rep->iterations += static_cast<int>(summary.iterations.size()) - 1;
      for (int64_t t = 0; t < d->N; ++t)  // the state at the solution (the cache may hold a rejected step's)
        if (!d->is_kept(t)) state_of(*d, d->p.data() + t * kX, d->x.data() + t * kX);
    };
    solve();
    // The separation term's active set grows within the round: a frame whose fingers the
    // solve brought inside the gap from further than kSeparationActive (pushed out of the
    // object sideways into each other) gets the term and the round's solve goes on. Without
    // it, such fingers ended the last round crossed (most of Implaus after the refinement).
    for (int pass = 0; pass < kSeparationPasses && o.w_separation > 0; ++pass) {
      int added = 0;
      for (int64_t t = 0; t < d->N; ++t)
        if (!separated[static_cast<size_t>(t)] && !d->is_kept(t) && near_gap(*d, t, o.separation_gap - kSeparationActive)) {
          add_separation(t, std::pow(d->pen_boost[static_cast<size_t>(t)], o.constraint_growth));
          ++added;
        }
      if (added == 0) break;
      rep->separation_frames_added += added;
      solve();
    }
    if (o.backtrack) rep->backtracked_frames += backtrack(d, all, dist, o, p_before);
    size_t rows = 0, pens = 0;
    for (const FrameTerms& f : d->frames) {
      rows += static_cast<size_t>(f.sub.size());
      pens += f.pen_rows.size();
    }
    // The limits as a constraint: the penalty steers, and every joint the solve left outside
    // its range is put back on its edge (a stiffer penalty makes Levenberg–Marquardt reject
    // the steps that cross it and stall, with the penetration boost growing behind it).
    if (o.w_limits > 0 || d->angles)
      for (int64_t t = 0; t < d->N; ++t)
        if (!d->is_kept(t) && !pinned_fingers.count(t)) rep->clamped_joints += d->limits->clamp_pose(d->x.data() + t * kX + 3);
    ++rep->outer_iterations;
    e = timed_evaluate(true, true);
    log::debug("refinement round {} (largest penetration boost {:g}): {} vertices and {} penetration planes per frame; deepest {:.1f} mm "
               "(frame {}, vertex {}); {}",
               outer + 1, e.max_boost, rows / static_cast<size_t>(d->N), pens / static_cast<size_t>(d->N),
               e.max_depth * 1e3, e.deepest_frame, e.deepest_vertex, summary.BriefReport());
  }
  // The terms as defined, at the nominal w_pen.
  rep->max_pen_boost = e.max_boost;  // boosts only grow: the last evaluation has the largest
  rep->after = e.terms;
  rep->max_depth_after = e.max_depth;
  rep->keypoint_error_after = e.keypoint_error;
  rep->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Per hand and frame, the part it is held to (HandData::hold_part): in a held (turning)
// frame, the starting hand nearer the object (its top part); the term only pulls a hand
// from outside, so one that touches or is inside costs nothing. The top part wins over the
// whole object for a hand chosen twice. A directed contact (RefineDirections::hold) holds
// its hand to its part over its frames, whichever hand is nearer: the penetration planes
// otherwise push a hand that should rest on a part off it.
void assign_holds(const std::array<const HandModel*, 2>& models, const ObjectDistance& dist,
                  const std::vector<ObjectState>& states, const HandMotion& start, const HeldFrames& held,
                  const RefineOptions& o, const RefineDirections& directions, std::array<HandData, 2>* data) {
  const std::size_t N = states.size();
  for (HandData& d : *data) d.hold_part.assign(N, -1);
  if (o.w_hold == 0) return;
  const auto kept = [&](std::size_t t) { return !directions.kept.empty() && directions.kept[t]; };
  for (int h = 0; h < 2; ++h) {
    const std::vector<int>& asked = directions.hold[static_cast<std::size_t>(h)];
    for (std::size_t t = 0; t < asked.size() && t < N; ++t)
      if (asked[t] >= 0 && !kept(t)) (*data)[static_cast<std::size_t>(h)].hold_part[t] = asked[t];
  }
  if (held.held.empty() && held.turning.empty()) return;
  if ((!held.held.empty() && held.held.size() != N) || (!held.turning.empty() && held.turning.size() != N))
    throw Error("refinement: held frames need " + std::to_string(N) + " flags each, got " +
                std::to_string(held.held.size()) + " and " + std::to_string(held.turning.size()));
  const at::Tensor V =
      (start.has_vertices() ? start.vertices : pose_hand_vertices(models, start)).to(at::kDouble).contiguous();
  const auto Vn = static_cast<Eigen::Index>(V.size(2));
  const std::pair<ObjectPart, const std::vector<bool>*> passes[] = {{ObjectPart::Whole, &held.held},
                                                                    {ObjectPart::Top, &held.turning}};
  const auto may = [&](ObjectPart part, std::size_t t, int h) {
    const at::Tensor& m = part == ObjectPart::Top ? directions.may_hold_top : directions.may_hold;
    return !m.defined() || m[static_cast<int64_t>(t)][h].item<bool>();
  };
  for (std::size_t t = 0; t < N; ++t)
    for (const auto& [part, flags] : passes) {
      if (flags->empty() || !(*flags)[t]) continue;
      if (kept(t)) continue;
      double sd[2];
      for (int h = 0; h < 2; ++h) {
        const Eigen::Map<const Points3> v(V[h][static_cast<int64_t>(t)].data_ptr<double>(), Vn, 3);
        sd[h] = may(part, t, h) ? dist.max_signed_distance(states[t], v, part) : -std::numeric_limits<double>::infinity();
      }
      if (!may(part, t, 0) && !may(part, t, 1)) continue;
      const int h = sd[0] >= sd[1] ? 0 : 1;
      const std::vector<int>& asked = directions.hold[static_cast<std::size_t>(h)];
      if (!asked.empty() && asked[t] >= 0) continue;  // held to its directed part already
      int& p = (*data)[static_cast<std::size_t>(h)].hold_part[t];
      if (part == ObjectPart::Top || p < 0) p = static_cast<int>(part);
    }
}

// The directions for hand h into its data, checked against its N frames.
void apply_directions(const RefineDirections& r, int h, HandData* d) {
  const std::size_t N = static_cast<std::size_t>(d->N);
  const auto& clear = r.clearance[static_cast<size_t>(h)];
  if (!clear.empty() && clear.size() != N)
    throw Error(fmt::format("refinement: {} clearances for {} frames", clear.size(), N));
  if (!r.kept.empty() && r.kept.size() != N) throw Error(fmt::format("refinement: {} kept flags for {} frames", r.kept.size(), N));
  const auto& hold = r.hold[static_cast<size_t>(h)];
  if (!hold.empty() && hold.size() != N) throw Error(fmt::format("refinement: {} held parts for {} frames", hold.size(), N));
  for (const int p : hold)
    if (p < -1 || p > static_cast<int>(ObjectPart::Whole)) throw Error(fmt::format("refinement: a held part {} (-1..2)", p));
  for (const at::Tensor* m : {&r.may_hold, &r.may_hold_top})
    if (m->defined() && (m->dim() != 2 || m->size(0) != d->N || m->size(1) != 2))
      throw Error("refinement: the hands that may hold must be [" + std::to_string(N) + ", 2], got " + c10::str(m->sizes()));
  d->clearance = clear.empty() ? std::vector<double>(N, 0.0) : clear;
  d->kept = r.kept;
  d->pins = r.pins[static_cast<size_t>(h)];
  for (const auto& p : d->pins)
    if (p.frame < 0 || p.frame >= d->N || (p.fingers && p.fingers->size() != 45))
      throw Error(fmt::format("refinement: a pin at frame {} of {} frames (with {} finger values)", p.frame, N,
                              p.fingers ? p.fingers->size() : 45));
  if (!(r.w_pin >= 0) || !std::isfinite(r.w_pin)) throw Error("refinement: w_pin must be a finite number >= 0");
  const Eigen::VectorXd zero_pose = Eigen::VectorXd::Zero(HandModel::kPoseDim);
  const Eigen::VectorXd beta = Eigen::Map<const Eigen::VectorXd>(d->beta.data(), HandModel::kNumBetas);
  d->j0 = lbs<double>(*d->model, Eigen::Vector3d::Zero(), zero_pose, Eigen::Vector3d::Zero(), beta).joints.row(0).transpose();
}

std::vector<double> as_vector(const at::Tensor& t) {
  const at::Tensor c = t.to(at::kCPU, at::kDouble).contiguous();
  return std::vector<double>(c.data_ptr<double>(), c.data_ptr<double>() + c.numel());
}

}  // namespace

void RefineOptions::validate() const {
  auto nonneg = [](double v, const char* name) {
    if (!(v >= 0) || !std::isfinite(v))
      throw Error(std::string("refinement: ") + name + " must be a finite number >= 0");
  };
  nonneg(w_proj, "w_proj");
  nonneg(w_pen, "w_pen");
  nonneg(w_acc, "w_acc");
  nonneg(w_fit, "w_fit");
  nonneg(w_hold, "w_hold");
  nonneg(w_limits, "w_limits");
  nonneg(w_pose, "w_pose");
  nonneg(w_separation, "w_separation");
  nonneg(separation_gap, "separation_gap");
  if (!(max_pen_boost >= 1)) throw Error("refinement: max_pen_boost must be >= 1");
  if (!(constraint_growth >= 0 && constraint_growth <= 1)) throw Error("refinement: constraint_growth must be in [0, 1]");
  nonneg(pen_margin, "pen_margin");
  if (!(pen_exit_depth >= 0)) throw Error("refinement: pen_exit_depth must be >= 0 (metres; 1e9 = off)");
  if (pen_exit_smooth < 0) throw Error("refinement: pen_exit_smooth must be >= 0 (frames)");
  if (outer_iterations < 0) throw Error("refinement: outer_iterations must be >= 0");
  if (max_outer_iterations < 0) throw Error("refinement: max_outer_iterations must be >= 0");
  nonneg(pen_tolerance, "pen_tolerance");
  if (!(pen_growth >= 1) || !std::isfinite(pen_growth)) throw Error("refinement: pen_growth must be >= 1");
  if (max_iterations < 0) throw Error("refinement: max_iterations must be >= 0");
  if (accel_vertices < 32) throw Error("refinement: accel_vertices must be >= 32 (2 per hand part)");
  if (threads < 0) throw Error("refinement: threads must be >= 0 (0 = all cores)");
}

HandMotion refine_hands(const std::array<const HandModel*, 2>& models, const ObjectDistance& distance, const at::Tensor& states,
                        const at::Tensor& keypoints, const HandMotion& start,
                        const RefineOptions& options, RefineReport* report, const HeldFrames& held,
                        const RefineDirections& directions) {
  options.validate();
  const int64_t N = start.num_frames();
  if (N < 1) throw Error("refinement: the starting motion has no frames");
  if (!keypoints.defined() || keypoints.dim() != 2 || keypoints.size(0) != N || keypoints.size(1) != kHandFeatureSize)
    throw Error("refinement: keypoints must be [" + std::to_string(N) + ", 1200] to match the motion's frames");
  if (!states.defined() || states.dim() != 2 || states.size(0) != N || states.size(1) != 7)
    throw Error("refinement: object states must be [" + std::to_string(N) + ", 7]");
  const at::Tensor X = keypoints.to(at::kCPU, at::kDouble).contiguous();
  if (first_out_of_bounds(X.data_ptr<double>(), static_cast<long>(X.numel()), kMaxCoordinate) >= 0)
    throw Error("refinement: keypoints hold values that are not finite or beyond 10 km (diverged input?)");
  const auto t0 = std::chrono::steady_clock::now();
  const at::Tensor st = states.to(at::kCPU, at::kDouble).contiguous();
  const HandKeypointsWorld w = hand_features_to_world(X, st);

  std::array<HandData, 2> data;
  for (int h = 0; h < 2; ++h) {
    HandData& d = data[static_cast<size_t>(h)];
    d.model = models[static_cast<size_t>(h)];
    d.limits.emplace(*d.model);
    d.angles = options.joint_angles;
    d.N = N;
    states_from_hand_motion(start, h, &d.x, &d.beta);
    d.H = as_vector(w.positions[h]);
    d.D = as_vector(w.directions[h]);
    for (int64_t t = 0; t < N; ++t) d.states.push_back(ObjectState::from_row(st[t].data_ptr<double>()));
    d.kp_ids = model_keypoints(*d.model);
    d.acc_ids = hand_keypoints(*d.model, options.accel_vertices);
    apply_directions(directions, h, &d);
  }
  assign_holds(models, distance, data[0].states, start, held, options, directions, &data);
  RefineReport local;
  parallel_for(2, resolve_threads(options.threads),
               [&](std::size_t h) { refine_hand(&data[h], distance, options, &local.hands[h], directions.w_pin); });

  HandMotion motion = hand_motion_from_states({data[0].x, data[1].x}, {data[0].beta, data[1].beta}, N);
  motion.vertices = pose_hand_vertices(models, motion);
  local.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (report) *report = local;
  return motion;
}

std::string format_refine_report(const RefineReport& r) {
  std::string out;
  for (int h = 0; h < 2; ++h) {
    const RefineHandReport& x = r.hands[static_cast<size_t>(h)];
    out += fmt::format(
        "{} hand: proj {:.3g} -> {:.3g}, pen {:.3g} -> {:.3g}, acc {:.3g} -> {:.3g}, fit {:.3g} -> {:.3g}, "
        "hold {:.3g} -> {:.3g} ({} frames), limits {:.3g} -> {:.3g} ({} joints clamped), pose {:.3g}, separation {:.3g} -> {:.3g} ({} frames added in rounds); {} steps cut back; "
        "deepest {:.1f} -> {:.1f} mm (penetration boost up to {:.3g}); keypoint error {:.1f} mm; {} steps in {} rounds, {:.2f} s ({:.2f} s surface)\n",
        h == 0 ? "left" : "right", x.before.proj, x.after.proj, x.before.pen, x.after.pen, x.before.acc,
        x.after.acc, x.before.fit, x.after.fit, x.before.hold, x.after.hold, x.held_frames, x.before.limits, x.after.limits, x.clamped_joints, x.after.pose, x.before.separation, x.after.separation, x.separation_frames_added, x.backtracked_frames, x.max_depth_before * 1e3, x.max_depth_after * 1e3,
        x.max_pen_boost, x.keypoint_error_after * 1e3, x.iterations, x.outer_iterations, x.seconds, x.surface_seconds);
  }
  return out;
}

}  // namespace bimart
